#include "daemon/commands/inputs.h"

#include <sys/prctl.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <iostream>

#include "core/common/clock.h"
#include "io/files/csv.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace {
void Report(const Diagnostics& diagnostics) {
  for (const Diagnostic& d : diagnostics) std::cerr << d.ToString() << "\n";
}
}  // namespace

bool LoadConfigOrReport(const std::string& path, Config* config) {
  Diagnostics errors;
  if (LoadConfig(path, config, &errors)) return true;
  Report(errors);
  return false;
}

bool DieWithParent(int parent_pid) {
  if (parent_pid <= 0) return true;
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  // The parent may have died before prctl took effect.
  if (::getppid() != parent_pid) {
    std::cerr << "--parent-pid " << parent_pid << ": the parent is gone\n";
    return false;
  }
  return true;
}

bool LoadCsvOrReport(const std::string& path, const Config& config, Series* series,
                     const NaiveTimeZone* naive_time_zone) {
  Diagnostics errors, warnings;
  CsvReadOptions options;
  options.naive_time_zone = naive_time_zone;
  options.fluid_density_kg_m3 = config.plant.fluid_density_kg_m3;
  options.area_m2 = config.plant.area_m2;
  const bool ok = ReadCanonicalCsv(path, options, series, &errors, &warnings);
  for (const Diagnostic& w : warnings) std::cerr << "warning: " << w.ToString() << "\n";
  Report(errors);
  return ok;
}

bool ParseVariantOrReport(const std::string& name, ModelSpec* spec) {
  std::string error;
  if (ParseVariant(name, spec, &error)) return true;
  std::cerr << "--variant = " << name << ": " << error << "\n";
  return false;
}

bool PrepareDriversOrReport(const Series& series, const std::string& csv_path, const Config& config,
                            const ModelSpec& spec, Drivers* drivers) {
  std::string error;
  if (PrepareDrivers(series, config.plant, spec, drivers, &error)) {
    if (spec.sky && !drivers->sky_note.empty()) {
      std::cerr << csv_path << ": note: " << drivers->sky_note << "\n";
    }
    return true;
  }
  std::cerr << csv_path << ": " << error << "\n";
  return false;
}

bool ParseTimeOrReport(const std::string& option, const std::string& text, std::int64_t* unix_s) {
  std::string error;
  const auto now_s = static_cast<std::int64_t>(std::floor(WallNowS()));
  if (ParseTimeArgument(text, now_s, unix_s, &error)) return true;
  std::cerr << option << " = " << text << ": " << error << "\n";
  return false;
}

bool WriteCsvOrReport(const std::string& out, const Series& series,
                      std::span<const Channel> channels) {
  if (out.empty() || out == "-") {
    WriteCsv(std::cout, series, channels);
    if (!std::cout) std::cerr << "writing CSV to standard output failed\n";
    return static_cast<bool>(std::cout);
  }
  std::string error;
  if (!WriteCsv(out, series, channels, &error)) {
    std::cerr << error << "\n";
    return false;
  }
  return true;
}

}  // namespace pvtwin::cli
