// pvtwin backtest: the paper's rolling evaluation (section 3.3) on a CSV.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "config/plant_config.h"
#include "core/common/calendar.h"
#include "core/forecast/backtest.h"
#include "core/forecast/forecast_backtest.h"
#include "core/model/variant.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/weather_import.h"
#include "io/report/backtest_report.h"
#include "io/platform/local_time.h"
#include "io/files/params_json.h"
#include "io/platform/quantity_text.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace {

struct BacktestArgs {
  std::string config;
  std::string csv;
  std::vector<std::string> variants;
  std::vector<int> train_days;
  std::vector<double> steps_s;
  std::string first_test_day;
  int test_days = 29;
  std::string json;
  int threads = 0;
  bool warm_start = false;
  // --forecast: the daily forecast's backtest instead of the fit's.
  bool forecast = false;
  std::string issue_at = "00:00";
  std::string weather;
  std::string params;
};

// "YYYY-MM-DD" → year, month, day. False unless it is a calendar date.
bool ParseDate(const std::string& text, int* year, int* month, int* day) {
  if (text.size() != 10 || text[4] != '-' || text[7] != '-') return false;
  for (std::size_t i : {0, 1, 2, 3, 5, 6, 8, 9}) {
    if (text[i] < '0' || text[i] > '9') return false;
  }
  *year = std::stoi(text.substr(0, 4));
  *month = std::stoi(text.substr(5, 2));
  *day = std::stoi(text.substr(8, 2));
  if (*month < 1 || *month > 12 || *day < 1) return false;
  static constexpr int kDaysInMonth[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (*year % 4 == 0 && *year % 100 != 0) || *year % 400 == 0;
  const int last = kDaysInMonth[*month - 1] + (*month == 2 && leap ? 1 : 0);
  return *day <= last;
}

// "paper" stands for the nine variants of Table 6.
std::vector<std::string> ExpandVariants(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const std::string& name : names) {
    if (name == "paper") {
      out.insert(out.end(), PaperVariants().begin(), PaperVariants().end());
    } else {
      out.push_back(name);
    }
  }
  return out;
}

void PrintProgress(int done, int total, const BacktestDay& day, std::int64_t solar_offset_s,
                   double area_m2) {
  const std::string date = SolarDate(day.day_start_s, solar_offset_s);
  if (day.ok) {
    std::fprintf(stderr, "[%d/%d] %s %s n=%d: MAE P_el %s, MAE Q_u %s (%.2f s)\n", done, total,
                 date.c_str(), day.variant.c_str(), day.train_days,
                 WattsAndPerM2(day.test.mae_p_el_w, area_m2).c_str(),
                 WattsAndPerM2(day.test.mae_q_th_w, area_m2).c_str(), day.runtime_s);
  } else {
    std::fprintf(stderr, "[%d/%d] %s %s n=%d: FAILED: %s\n", done, total, date.c_str(),
                 day.variant.c_str(), day.train_days, day.failure_reason.c_str());
  }
}

// The issue times: the first local issue_at on or after the first test day's
// start, then one a day, while the data reach into the horizon.
bool IssueTimes(const BacktestArgs& a, const Config& config, const Series& series,
                std::int64_t first_day_start, std::vector<std::int64_t>* out) {
  int hour = 0, minute = 0;
  std::string error;
  if (!ParseClockTime(a.issue_at, &hour, &minute)) {
    std::cerr << "--issue-at = " << a.issue_at << ": expected HH:MM (local time of [calibration] "
              << "timezone)\n";
    return false;
  }
  if (!UseTimeZone(config.calibration.timezone, &error)) {
    std::cerr << a.config << ": [calibration] timezone = " << config.calibration.timezone << ": "
              << error << "\n";
    return false;
  }
  std::int64_t t = NextLocalTime(first_day_start - 1, hour, minute);
  for (int k = 0; k < a.test_days && t < series.time_s.back(); ++k) {
    out->push_back(t);
    t = NextLocalTime(t, hour, minute);
  }
  return true;
}

int RunForecastBacktestCommand(const BacktestArgs& a, const Config& config, const Series& series,
                               std::optional<std::int64_t> first_test_day_s) {
  ForecastBacktestOptions options;
  std::string error;
  const std::string variant = a.variants.empty() ? config.calibration.variant : a.variants[0];
  if (!ParseVariant(variant, &options.spec, &error)) {
    std::cerr << "--variants = " << variant << ": " << error << "\n";
    return kExitBadInput;
  }
  options.window_days = a.train_days.empty() ? config.calibration.window_days : a.train_days[0];
  if (series.step_s != 60.0) {
    std::cerr << a.csv << ": backtest --forecast needs 1-min rows, as the daemon forecasts; the "
              << "file's step is " << series.step_s << " s\n";
    return kExitBadInput;
  }
  if (!a.params.empty()) {
    options.fixed_params = true;
    ParamsFile file;
    file.values = StartParams(config.plant);
    Diagnostics errors;
    if (!ReadParamsJson(a.params, config.plant, &file, &errors)) {
      for (const Diagnostic& d : errors) std::cerr << d.ToString() << "\n";
      return kExitBadInput;
    }
    options.params = file.values;
  }
  Series weather;
  if (!a.weather.empty()) {
    std::ifstream in(a.weather, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    WeatherImportResult r;
    if (!in || !WeatherTextTo1Min(config.plant, text.str(), a.weather, &r, &weather)) {
      if (!in) std::cerr << a.weather << ": cannot be read\n";
      for (const Diagnostic& d : r.errors) std::cerr << d.ToString() << "\n";
      return kExitBadInput;
    }
    std::cerr << "weather forecast " << a.weather << " (" << r.file.format
              << "): " << weather.size() << " 1-min rows\n";
    for (const std::string& warning : r.Warnings()) std::cerr << "warning: " << warning << "\n";
  }
  const std::int64_t offset_s = SolarDayOffsetS(config.plant);
  const std::int64_t first_day =
      first_test_day_s ? *first_test_day_s
                       : SolarDayStartS(series.time_s.front(), offset_s) +
                             static_cast<std::int64_t>(options.window_days) * kSecondsPerDay;
  if (!IssueTimes(a, config, series, first_day, &options.issue_times_s)) return kExitBadInput;
  if (options.issue_times_s.empty()) {
    std::cerr << a.csv << ": no issue time with " << options.window_days
              << " days of data before it and data after it\n";
    return kExitBadInput;
  }
  ForecastBacktestResult result;
  const auto progress = [](int done, int total, const ForecastBacktestDay& d) {
    if (d.ok) {
      std::fprintf(stderr, "[%d/%d] forecast issued %s: skill P_el %.3f, Q_u %.3f\n", done, total,
                   FormatIsoUtc(d.issued_at_s).c_str(), d.p_el.skill, d.q_th.skill);
    } else {
      std::fprintf(stderr, "[%d/%d] forecast issued %s: not scored: %s\n", done, total,
                   FormatIsoUtc(d.issued_at_s).c_str(), d.failure.c_str());
    }
  };
  if (!RunForecastBacktest(series, weather, config.plant, options, &result, &error, progress)) {
    std::cerr << error << "\n";
    return kExitBadInput;
  }
  std::cout << FormatForecastBacktest(result) << "\nall days: MAE P_el "
            << WattsAndPerM2(result.total_p_el.mae_w, config.plant.area_m2) << ", MAE Q_u "
            << WattsAndPerM2(result.total_q_th.mae_w, config.plant.area_m2) << "\n";
  std::cout.flush();
  return result.days_ok > 0 ? kExitOk : kExitRuntime;
}

int RunBacktestCommand(const BacktestArgs& a) {
  // Every variant name first, each bad one reported.
  Config config;
  const std::vector<std::string> variants = ExpandVariants(a.variants);
  bool names_ok = true;
  for (const std::string& name : variants) {
    ModelSpec spec;
    std::string error;
    if (!ParseVariant(name, &spec, &error)) {
      std::cerr << "--variants = " << name << ": " << error << "\n";
      names_ok = false;
    }
  }
  int year = 0, month = 0, day = 0;
  if (!a.first_test_day.empty() && !ParseDate(a.first_test_day, &year, &month, &day)) {
    std::cerr << "--first-test-day = " << a.first_test_day
              << ": expected a calendar date YYYY-MM-DD (the local solar day of that date)\n";
    names_ok = false;
  }
  if (!names_ok) return kExitBadInput;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;

  BacktestOptions options;
  options.variants =
      variants.empty() ? std::vector<std::string>{config.calibration.variant} : variants;
  options.train_days =
      a.train_days.empty() ? std::vector<int>{config.calibration.window_days} : a.train_days;
  options.test_days = a.test_days;
  options.threads = a.threads;
  options.warm_start = a.warm_start;
  if (!a.first_test_day.empty()) {
    options.first_test_day_s =
        SolarDayStartOfDateS(year, month, day, SolarDayOffsetS(config.plant));
  }
  Series series;
  if (!LoadCsvOrReport(a.csv, config, &series)) return kExitBadInput;
  if (a.forecast) return RunForecastBacktestCommand(a, config, series, options.first_test_day_s);
  // Default: the data's own step, as the file holds them.
  const std::vector<double> steps_s =
      a.steps_s.empty() ? std::vector<double>{series.step_s} : a.steps_s;
  bool options_ok = true;
  for (double step_s : steps_s) {
    options.step_s = step_s;
    std::string why;
    if (!options.IsValid(&why)) {
      std::cerr << "backtest: " << why
                << (a.steps_s.empty() ? " (the data's step; give --step)" : "") << "\n";
      options_ok = false;
    }
  }
  if (!options_ok) return kExitBadInput;

  std::vector<BacktestResult> results;
  for (double step_s : steps_s) {
    options.step_s = step_s;
    if (steps_s.size() > 1) std::fprintf(stderr, "backtest at a step of %g s\n", step_s);
    const std::int64_t offset_s = SolarDayOffsetS(config.plant);
    BacktestResult result;
    std::string error;
    const bool ok = RunBacktest(series, config.plant, options, &result, &error,
                                [offset_s, &config](int done, int total, const BacktestDay& d) {
                                  PrintProgress(done, total, d, offset_s, config.plant.area_m2);
                                });
    if (!ok) {
      std::cerr << a.csv << ": " << error << "\n";
      return kExitBadInput;
    }
    if (result.skipped_days > 0) {
      std::fprintf(stderr, "%d of the test days hold no data across solar noon: skipped\n",
                   result.skipped_days);
    }
    std::cout << FormatBacktestTables(result) << "\n";
    results.push_back(std::move(result));
  }
  if (results.size() > 1) std::cout << FormatStepTable(results);
  std::cout.flush();

  if (!a.json.empty()) {
    std::string error;
    if (!WriteTextFileAtomically(a.json, BacktestReportJson(results), &error)) {
      std::cerr << error << "\n";
      return kExitRuntime;
    }
    std::cerr << "wrote " << a.json << "\n";
  }

  int jobs = 0, ok_jobs = 0, too_little_data = 0;
  for (const BacktestResult& r : results) {
    for (const BacktestDay& d : r.days) {
      ++jobs;
      ok_jobs += d.ok;
      too_little_data += d.failure == BacktestFailure::kTooLittleData;
    }
  }
  if (too_little_data > 0) {
    std::cerr << a.csv << ": " << too_little_data << " of " << jobs
              << " jobs had too little data (see \"Failed days\"); fewer than "
              << options.ident.min_rows << " usable rows in the test day or training window\n";
    return kExitBadInput;
  }
  if (ok_jobs == 0) {
    std::cerr << "backtest: no identification succeeded\n";
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace

void RegisterBacktest(CLI::App& app) {
  auto args = std::make_shared<BacktestArgs>();
  CLI::App* cmd = app.add_subcommand(
      "backtest",
      "The paper's rolling evaluation (section 3.3): for each test day, identify each variant\n"
      "on the n days before it, predict the test day from its measured inputs and score it.\n"
      "Days are local mean solar days (midnight at 00:00 UTC - longitude/15 h). Progress on\n"
      "stderr, tables shaped like the paper's Tables 4, 5 and 6 on stdout.\n"
      "Exit 0 success, 2 bad input (bad variant, missing columns, too little data in a test\n"
      "day or training window: the tables are still printed), 1 no identification succeeded\n"
      "or the report could not be written.");
  cmd->add_option("--config", args->config, "TOML config with the [plant] section")->required();
  cmd->add_option("--csv", args->csv, "canonical CSV with the measurements")->required();
  cmd->add_option("--variants", args->variants,
                  "comma-separated variants, or 'paper' for the nine of Table 6 "
                  "(default: [calibration] variant)")
      ->delimiter(',');
  cmd->add_option("--train-days", args->train_days,
                  "comma-separated training periods n in days, e.g. 7,14,21,28 "
                  "(default: [calibration] window_days)")
      ->delimiter(',');
  cmd->add_option("--step", args->steps_s,
                  "time step in s (5 ... 900, a multiple of the data step); several, comma-"
                  "separated, add a Table 5-shaped comparison (default: the data's step)")
      ->delimiter(',');
  cmd->add_option("--first-test-day", args->first_test_day,
                  "first test day YYYY-MM-DD, the local solar day of that date (default: the "
                  "first day with max(n) days of data before it)");
  cmd->add_option("--test-days", args->test_days,
                  "number of consecutive test days; fewer if the data end (default 29)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", args->json, "write the report (every job and the means) as JSON");
  cmd->add_option("--threads", args->threads, "worker threads, 0 = all cores (default 0)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--warm-start", args->warm_start,
                "start each day's identification from the parameters the same variant "
                "identified the day before, as the daemon re-identifies nightly (the first day, "
                "and a day after a failed one, from Table 3); default: every day from Table 3");
  cmd->add_flag("--forecast", args->forecast,
                "backtest the daily 24 h forecast instead of the fit: for each test day, "
                "identify on the window before the issue (the first --train-days, default "
                "[calibration] window_days), issue the forecast as the daemon does and score it "
                "against the measured day: MAE, skill against smart persistence and the 10-90 % "
                "band's coverage. Needs 1-min rows. Example: pvtwin backtest --forecast "
                "--config plant.toml --csv plant.csv --weather forecast.json --test-days 14");
  cmd->add_option("--issue-at", args->issue_at,
                  "with --forecast: local time HH:MM of [calibration] timezone at which each "
                  "day's forecast is issued (default 00:00)");
  cmd->add_option("--weather", args->weather,
                  "with --forecast: a weather forecast file (Open-Meteo JSON or canonical CSV, as "
                  "import-weather reads) for the horizons and the replayed days; without it "
                  "the weather is persisted");
  cmd->add_option("--params", args->params,
                  "with --forecast: fixed parameters (JSON of calibrate) instead of identifying "
                  "each day");
  cmd->callback([args] { SetExitCode(RunBacktestCommand(*args)); });
}

}  // namespace pvtwin::cli
