// libFuzzer harness for the config reader (config/plant_config.h): TOML
// parsing, every section and key, the register map. It must never crash; a
// config it accepts must hold values within their documented bounds, and a
// config it refuses must say why at a line. Seeds: tests/fuzz/corpus/config/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/plant_config.h"

namespace {

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pvtwin::Config config;
  pvtwin::Diagnostics errors;
  const bool ok = pvtwin::ParseConfig(text, "fuzz.toml", &config, &errors);
  Require(ok == errors.empty());
  for (const pvtwin::Diagnostic& d : errors) Require(!d.ToString().empty());
  if (!ok) return 0;
  // The bounds the daemon relies on (plant_config.h).
  const double period_s = config.poll.period_s;
  Require(period_s >= 1 && period_s <= 60 && std::fmod(60.0, period_s) == 0.0);
  Require(config.plant.area_m2 > 0 && config.plant.area_m2 <= 1e6);
  Require(config.plant.fluid_cp_j_kgk >= 1000 && config.plant.fluid_cp_j_kgk <= 5000);
  Require(config.storage.raw_retention_days >= 1 && config.storage.raw_retention_days <= 3650);
  Require(config.forecast.refresh_min >= 1 && config.forecast.refresh_min <= 1440);
  Require(config.calibration.window_days >= 1 && config.calibration.window_days <= 60);
  for (const pvtwin::ModbusPoint& p : config.modbus.points) {
    Require(std::isfinite(p.scale) && p.scale != 0.0 && std::isfinite(p.offset));
  }
  return 0;
}
