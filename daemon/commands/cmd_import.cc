// pvtwin import: canonical CSV into the SQLite store. A CSV with a step of 5 s
// (any whole divisor of 60 s) holds poll samples: they go to sample_5s and
// their minutes are (re-)aggregated into measurement_1min. A CSV with a step
// of 60 s holds 1-min rows: they go to measurement_1min directly. A CSV of a
// coarser logger (2, 10, 15 min: any whole number of minutes up to 1 h)
// goes to measurement_interval at its own step: 1-min rows made from it
// would invent what happened inside each interval. All are upserts, so
// importing the same or overlapping data again leaves one row per time.
// Then the closed days of forecast_skill whose minutes changed are
// materialised again (Store::RefreshForecastSkill).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>

#include "core/common/clock.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/store_cli.h"
#include "io/store/store.h"

namespace pvtwin::cli {

namespace {

struct ImportArgs {
  std::string config;
  std::string csv;
  std::string db;
  std::string timezone;
};

// Rows per transaction: one day of 5 s samples, one day of 1-min rows.
constexpr std::size_t kSampleBatch = 17280;
constexpr std::size_t kMinuteBatch = 1440;

// Progress on stderr, every batch, for inputs of more than two batches.
void PrintImportProgress(const char* what, std::size_t done, std::size_t total, std::size_t batch) {
  if (total > 2 * batch) {
    std::cerr << "import: " << done << "/" << total << " " << what << " (" << (100 * done / total)
              << " %)\n";
  }
}

int ImportSamples(Store& store, const Series& series, const std::string& csv) {
  const std::vector<Sample> samples = SamplesFromSeries(series);
  int minutes_total = 0;
  std::string error;
  for (std::size_t begin = 0; begin < samples.size(); begin += kSampleBatch) {
    const std::size_t end = std::min(samples.size(), begin + kSampleBatch);
    const std::vector<Sample> batch(samples.begin() + static_cast<std::ptrdiff_t>(begin),
                                    samples.begin() + static_cast<std::ptrdiff_t>(end));
    int minutes = 0;
    // Re-aggregating the batch's minutes also takes in samples stored
    // earlier in the same minutes, so an overlapping import yields the
    // same rows as one import of everything.
    if (!store.InsertSamples(batch, &error) ||
        !store.ReaggregateMinutes(batch.front().ts_s,
                                  batch.back().ts_s + static_cast<std::int64_t>(series.step_s),
                                  &minutes, &error)) {
      std::cerr << csv << ": " << error << "\n";
      return kExitRuntime;
    }
    minutes_total += minutes;
    PrintImportProgress("samples", end, samples.size(), kSampleBatch);
  }
  std::cerr << "imported " << samples.size() << " samples (" << series.step_s
            << " s) into sample_5s and aggregated " << minutes_total
            << " minutes into measurement_1min of " << store.path() << "\n";
  return kExitOk;
}

// Moves rows to the nearest minute start (a logger's clock often writes
// hh:mm:01); two rows on one minute are an error.
bool AlignToMinutes(Series* series, const std::string& csv) {
  std::int64_t max_shift_s = 0;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < series->size(); ++i) {
    std::int64_t& t = series->time_s[i];
    const auto aligned = static_cast<std::int64_t>(
        std::llround(static_cast<double>(t) / static_cast<double>(kMinuteS)) * kMinuteS);
    if (aligned != t) {
      ++moved;
      max_shift_s = std::max(max_shift_s, std::abs(aligned - t));
      t = aligned;
    }
    if (i > 0 && t <= series->time_s[i - 1]) {
      std::cerr << csv << ":" << i + 2 << ": time: two rows fall on the minute " << t
                << " (rows must be 1 min apart)\n";
      return false;
    }
  }
  if (moved > 0) {
    std::cerr << "warning: " << csv << ": " << moved
              << " rows not at a minute start were moved to the nearest one (by up to "
              << max_shift_s << " s)\n";
  }
  return true;
}

int ImportMinutes(Store& store, Series series, const std::string& csv) {
  if (!AlignToMinutes(&series, csv)) return kExitBadInput;
  std::string error;
  for (std::size_t begin = 0; begin < series.size(); begin += kMinuteBatch) {
    const std::size_t end = std::min(series.size(), begin + kMinuteBatch);
    if (!store.WriteMinutes(series.Slice(begin, end), &error)) {
      std::cerr << csv << ": " << error << "\n";
      return kExitRuntime;
    }
    PrintImportProgress("1-min rows", end, series.size(), kMinuteBatch);
  }
  std::cerr << "imported " << series.size() << " 1-min rows into measurement_1min of "
            << store.path() << "\n";
  return kExitOk;
}

int ImportIntervals(Store& store, Series series, const std::string& csv) {
  if (!AlignToMinutes(&series, csv)) return kExitBadInput;
  std::string error;
  for (std::size_t begin = 0; begin < series.size(); begin += kMinuteBatch) {
    const std::size_t end = std::min(series.size(), begin + kMinuteBatch);
    if (!store.WriteIntervalRows(series.Slice(begin, end), &error)) {
      std::cerr << csv << ": " << error << "\n";
      return kExitRuntime;
    }
    PrintImportProgress("rows", end, series.size(), kMinuteBatch);
  }
  const int step_min = static_cast<int>(series.step_s) / kMinuteS;
  std::cerr << "imported " << series.size() << " rows of " << step_min
            << "-min data into measurement_interval of " << store.path()
            << ", at their own step: 1-min rows made from them would invent the values inside "
               "each interval, so measurement_1min is left as it was. The daemon's calibration, "
               "daily checks and forecast and diagnose --db read these rows at their step where "
               "a window has no 1-min rows; export --table interval gives them back.\n";
  return kExitOk;
}

// forecast_skill materialised again for the closed days the import changed
// (their rows marked them dirty), so that its readers do not compute them
// until the daemon's next daily checks.
int RefreshSkill(Store& store) {
  std::string error;
  if (!store.RefreshForecastSkill(static_cast<std::int64_t>(WallNowS()), nullptr, &error)) {
    std::cerr << "import: the rows are stored, but forecast_skill_day was not refreshed: " << error
              << "\n";
    return kExitRuntime;
  }
  return kExitOk;
}

enum class ImportKind { kSamples, kMinutes, kIntervals };

// Where rows of this step go; nullopt (and the message) when nowhere.
std::optional<ImportKind> KindOfStep(double step_s, const std::string& csv) {
  const bool whole = step_s >= 1.0 && step_s == std::floor(step_s);
  const auto minute = static_cast<double>(kMinuteS);
  if (step_s == minute) return ImportKind::kMinutes;
  if (whole && step_s < minute && std::fmod(minute, step_s) == 0.0) return ImportKind::kSamples;
  if (whole && step_s > minute && step_s <= 3600.0 && std::fmod(step_s, minute) == 0.0) {
    return ImportKind::kIntervals;
  }
  std::cerr << csv << ": time step = " << step_s
            << " s (median spacing of the rows): expected poll samples (a whole divisor of 60 s, "
               "e.g. 5 s), 1-min rows (60 s) or logger intervals of whole minutes up to 1 h "
               "(e.g. 2, 10, 15 min)\n";
  return std::nullopt;
}

int RunImport(const ImportArgs& a) {
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  std::optional<NaiveTimeZone> zone;
  if (!a.timezone.empty()) {
    std::string error;
    zone = NaiveTimeZone::Parse(a.timezone, &error);
    if (!zone) {
      std::cerr << "--timezone = " << error << "\n";
      return kExitBadInput;
    }
  }
  Series series;
  if (!LoadCsvOrReport(a.csv, config, &series, zone ? &*zone : nullptr)) return kExitBadInput;
  if (series.size() < 2) {
    std::cerr << a.csv << ": " << series.size()
              << " data rows: need at least 2 to tell the time step\n";
    return kExitBadInput;
  }
  const std::optional<ImportKind> kind = KindOfStep(series.step_s, a.csv);
  if (!kind) return kExitBadInput;
  StoreOptions options = StoreOptionsFor(config);
  if (*kind == ImportKind::kSamples) options.aggregate.sample_period_s = series.step_s;
  std::unique_ptr<Store> store;
  if (!OpenStoreOrReport(a.db.empty() ? config.storage.path : a.db, options, &store)) {
    return kExitRuntime;
  }
  int code = kExitRuntime;
  switch (*kind) {
    case ImportKind::kSamples:
      code = ImportSamples(*store, series, a.csv);
      break;
    case ImportKind::kMinutes:
      code = ImportMinutes(*store, series, a.csv);
      break;
    case ImportKind::kIntervals:
      code = ImportIntervals(*store, series, a.csv);
      break;
  }
  return code == kExitOk ? RefreshSkill(*store) : code;
}

}  // namespace

void RegisterImport(CLI::App& app) {
  auto args = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import",
      "Load a canonical CSV into the SQLite store ([storage] path of the config, or --db).\n"
      "The time step decides where rows go: 5 s data (any whole divisor of 60 s) are poll\n"
      "samples for sample_5s, and their minutes are aggregated into measurement_1min;\n"
      "1-min data go to measurement_1min directly (rows off the minute are moved to the\n"
      "nearest minute start, with a warning); data of a coarser logger (2, 10, 15 min, any\n"
      "whole number of minutes up to 1 h) go to measurement_interval at their own step, as\n"
      "1-min rows made from them would invent values. Rows are upserted: importing the same\n"
      "or overlapping data again leaves one row per time. Progress goes to stderr.");
  cmd->add_option("--config", args->config, "TOML config ([plant] fluid data, [storage] path)")
      ->required();
  cmd->add_option("--csv", args->csv, "canonical CSV to load")->required();
  cmd->add_option("--db", args->db, "SQLite file to use instead of [storage] path");
  cmd->add_option("--timezone", args->timezone,
                  "zone of time stamps without Z or offset: a tz database zone such as "
                  "Europe/Vienna (daylight saving time included) or a fixed offset such as "
                  "+01:00 (default: none, such time stamps are an error)");
  cmd->callback([args] { SetExitCode(RunImport(*args)); });
}

}  // namespace pvtwin::cli
