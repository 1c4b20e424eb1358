#include "daemon/commands/commands.h"

#include <string>
#include <utility>
#include <vector>

#include "core/diagnosis/effect_candidates.h"
#include "core/model/variant.h"

namespace pvtwin::cli {

namespace {
int g_exit_code = kExitOk;
}  // namespace

int ExitCode() { return g_exit_code; }
void SetExitCode(int code) { g_exit_code = code; }

namespace {

// One example per verb, shown under its --help (the config and CSV paths are
// the repository's examples and the real htw saar days).
const std::vector<std::pair<std::string, std::string>>& Examples() {
  static const std::vector<std::pair<std::string, std::string>> examples = {
      {"check-config", "pvtwin check-config /etc/pvtwin/pvtwin.toml"},
      {"calibrate",
       "pvtwin calibrate --config plant.toml --csv day3.csv --variant 2N1CcolwrI "
       "--test-csv day1.csv --out params.json"},
      {"simulate",
       "pvtwin simulate --config plant.toml --csv day1.csv --variant 2N1CcolwrI "
       "--params params.json --out pred.csv"},
      {"backtest",
       "pvtwin backtest --config plant.toml --csv data.csv --variants paper --train-days 14"},
      {"import",
       "pvtwin import --config /etc/pvtwin/pvtwin.toml --csv logger.csv --timezone Europe/Vienna"},
      {"import-weather",
       "pvtwin import-weather --db /var/lib/pvtwin/pvtwin.db forecast.json   # from "
       "https://api.open-meteo.com/v1/forecast?latitude=47.36&longitude=16.13&hourly="
       "shortwave_radiation,diffuse_radiation,temperature_2m,wind_speed_10m,dew_point_2m,"
       "cloud_cover&wind_speed_unit=ms&timezone=GMT"},
      {"export",
       "pvtwin export --db /var/lib/pvtwin/pvtwin.db --from -14d --out last-two-weeks.csv"},
      {"sim", "pvtwin sim --config config/examples/sim-plant.toml --speed 10"},
      {"run", "pvtwin run --config /etc/pvtwin/pvtwin.toml"},
      {"demo", "pvtwin demo --date 2026-06-20"},
      {"diagnose",
       "pvtwin diagnose --config plant.toml --csv data.csv --variant 1N1Cwr --report out/"},
      {"diagnose-selftest", "pvtwin diagnose-selftest --seeds 5 --jobs 2"},
      {"upload", "pvtwin upload --once --config /etc/pvtwin/pvtwin.toml"},
      {"poll", "pvtwin poll --once --config /etc/pvtwin/pvtwin.toml"},
      {"migrate",
       "pvtwin migrate --db /var/lib/pvtwin/pvtwin.db   # as the service user: sudo -u pvtwin"},
  };
  return examples;
}

// One line per verb for the top-level help (the verb's --help has the rest).
const std::vector<std::pair<std::string, std::string>>& Summaries() {
  static const std::vector<std::pair<std::string, std::string>> summaries = {
      {"check-config", "Validate a pvtwin config file (TOML) and exit"},
      {"calibrate", "Identify a model variant's parameters from operation data"},
      {"simulate", "Run a model variant with given parameters over measured inputs"},
      {"backtest", "The paper's rolling evaluation of variants, day by day"},
      {"import", "Load a canonical CSV into the SQLite store"},
      {"import-weather", "Load a weather forecast (Open-Meteo JSON or CSV) into the store"},
      {"export", "Write a time range of the SQLite store as canonical CSV"},
      {"sim", "The plant simulator: a simulated PVT plant behind real Modbus servers"},
      {"run", "Run the daemon: poll, store, calibrate nightly, forecast"},
      {"demo", "Run the whole job on the built-in example plant"},
      {"diagnose", "Sim-to-real gap diagnosis: which effect the model misses"},
      {"diagnose-selftest", "Proof of the diagnosis on synthetic data with a known answer"},
      {"upload", "Replicate the store into the central PostgreSQL"},
      {"poll", "Read every Modbus device once and show values, registers, rejections"},
      {"migrate", "Upgrade the SQLite store to this pvtwin's schema"},
  };
  return summaries;
}

// The variant grammar, for the verbs that take a variant.
std::string VariantHelp() {
  std::string paper;
  for (const std::string& v : PaperVariants()) paper += (paper.empty() ? "" : ", ") + v;
  std::string effects;
  for (const std::string& e : EffectNames()) effects += (effects.empty() ? "" : ", ") + e;
  return "Variants: the nine of the paper's Table 6 (" + paper +
         "): 1N/2N one or two temperature nodes; 1C/2C a capacitance on the PV node (1Cpv, or 1C "
         "with one node), the collector node (1Ccol) or both (2C); w wind-dependent front loss; r "
         "sky long-wave radiation; I beam/diffuse split with the incidence-angle modifier. Add "
         "effects of the library with +name, e.g. 1N1Cwr+transport_delay: " +
         effects + ".";
}

}  // namespace

std::string VerbSummary(const std::string& verb) {
  for (const auto& [name, summary] : Summaries()) {
    if (name == verb) return summary;
  }
  return "";
}

void RegisterCommands(CLI::App& app) {
  // Every option's default is shown in --help.
  app.option_defaults()->always_capture_default();
  RegisterCheckConfig(app);
  RegisterCalibrate(app);
  RegisterSimulate(app);
  RegisterBacktest(app);
  RegisterImport(app);
  RegisterImportWeather(app);
  RegisterExport(app);
  RegisterSim(app);
  RegisterRun(app);
  RegisterDemo(app);
  RegisterDiagnose(app);
  RegisterUpload(app);
  RegisterPoll(app);
  RegisterMigrate(app);
  for (const auto& [verb, example] : Examples()) {
    CLI::App* cmd = app.get_subcommand(verb);
    std::string footer = "\nExample:\n  " + example;
    if (verb == "calibrate" || verb == "simulate" || verb == "backtest" || verb == "diagnose") {
      footer += "\n\n" + VariantHelp();
    }
    cmd->footer(footer);
  }
}

}  // namespace pvtwin::cli
