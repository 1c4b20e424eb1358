// pvtwin check-config FILE: load and validate a config without starting
// anything. Exit 0 with a one-line summary on stdout, or exit 2 with every
// problem on stderr as "file:line: key = value: rule".
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "daemon/commands/commands.h"

namespace pvtwin::cli {
namespace {

// A number with up to six significant digits ("47.358", "1.8", "180").
std::string Short(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string Summary(const Config& config) {
  const Plant& p = config.plant;
  const double lat_deg = RadToDeg(p.latitude_rad);
  const double lon_deg = RadToDeg(p.longitude_rad);
  return config.source_path + ": ok (plant " + Short(p.area_m2) + " m² at " +
         Short(std::fabs(lat_deg)) + "°" + (lat_deg < 0 ? "S" : "N") + " " +
         Short(std::fabs(lon_deg)) + "°" + (lon_deg < 0 ? "W" : "E") + ", tilt " +
         Short(RadToDeg(p.tilt_rad)) + "°, azimuth " + Short(RadToDeg(p.azimuth_rad)) +
         "°; calibration " + config.calibration.variant + " daily at " + config.calibration.at +
         " " + config.calibration.timezone + ")";
}

}  // namespace

void RegisterCheckConfig(CLI::App& app) {
  auto file = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "check-config",
      "Validate a pvtwin config file (TOML) and exit.\n"
      "Checks [plant] (site, orientation, fluid and PV reference data), [storage], [poll],\n"
      "[calibration] and [forecast]; unknown sections and keys are errors.\n"
      "Valid: prints a one-line summary to stdout and exits 0.\n"
      "Invalid: prints every problem to stderr as 'file:line: key = value: rule', exits 2.");
  cmd->add_option("FILE", *file, "Config file to check, e.g. /etc/pvtwin/pvtwin.toml")->required();
  cmd->callback([file] {
    Config config;
    Diagnostics errors;
    if (!LoadConfig(*file, &config, &errors)) {
      for (const Diagnostic& d : errors) std::cerr << d.ToString() << '\n';
      SetExitCode(kExitBadInput);
      return;
    }
    std::cout << Summary(config) << '\n';
    SetExitCode(kExitOk);
  });
}

}  // namespace pvtwin::cli
