// pvtwin import: canonical CSV into the SQLite store. A CSV with a step of 5 s
// (any whole divisor of 60 s) holds poll samples: they go to sample_5s and
// their minutes are (re-)aggregated into measurement_1min. A CSV with a step
// of 60 s holds 1-min rows: they go to measurement_1min directly. Both are
// upserts, so importing the same or overlapping data again leaves one row per
// time.
#include <algorithm>
#include <cmath>
#include <iostream>

#include "daemon/commands.h"
#include "daemon/inputs.h"
#include "daemon/store_cli.h"
#include "io/store.h"

namespace pvtwin::cli {

namespace {

struct ImportArgs {
  std::string config;
  std::string csv;
  std::string db;
};

// Rows per transaction: one day of 5 s samples, one day of 1-min rows.
constexpr std::size_t kSampleBatch = 17280;
constexpr std::size_t kMinuteBatch = 1440;

// Progress on stderr, every batch, for inputs of more than two batches.
void Progress(const char* what, std::size_t done, std::size_t total, std::size_t batch) {
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
    Progress("samples", end, samples.size(), kSampleBatch);
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
    Progress("1-min rows", end, series.size(), kMinuteBatch);
  }
  std::cerr << "imported " << series.size() << " 1-min rows into measurement_1min of "
            << store.path() << "\n";
  return kExitOk;
}

int RunImport(const ImportArgs& a) {
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  Series series;
  if (!LoadCsvOrReport(a.csv, config, &series)) return kExitBadInput;
  if (series.size() < 2) {
    std::cerr << a.csv << ": " << series.size()
              << " data rows: need at least 2 to tell 5 s samples from 1-min rows\n";
    return kExitBadInput;
  }
  const double step_s = series.step_s;
  const bool minutes = step_s == static_cast<double>(kMinuteS);
  const bool samples = !minutes && step_s >= 1.0 && step_s == std::floor(step_s) &&
                       std::fmod(static_cast<double>(kMinuteS), step_s) == 0.0;
  if (!minutes && !samples) {
    std::cerr << a.csv << ": time step = " << step_s
              << " s (median spacing of the rows): expected 5 s samples (any whole divisor of "
                 "60 s) or 1-min rows (60 s)\n";
    return kExitBadInput;
  }
  StoreOptions options = StoreOptionsFor(config);
  if (samples) options.aggregate.sample_period_s = step_s;
  std::unique_ptr<Store> store;
  if (!OpenStoreOrReport(a.db.empty() ? config.storage.path : a.db, options, &store)) {
    return kExitRuntime;
  }
  return samples ? ImportSamples(*store, series, a.csv) : ImportMinutes(*store, series, a.csv);
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
      "nearest minute start, with a warning). Rows are upserted: importing the same or\n"
      "overlapping data again leaves one row per time. Progress goes to stderr.");
  cmd->add_option("--config", args->config, "TOML config ([plant] fluid data, [storage] path)")
      ->required();
  cmd->add_option("--csv", args->csv, "canonical CSV to load")->required();
  cmd->add_option("--db", args->db, "SQLite file to use instead of [storage] path");
  cmd->callback([args] { SetExitCode(RunImport(*args)); });
}

}  // namespace pvtwin::cli
