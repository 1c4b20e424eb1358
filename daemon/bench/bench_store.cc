// pvtwin-bench store: the SQLite store at the daemon's data rates, on 14
// days of synthetic 5 s samples (2N1Ccolwr truth with realistic sensor noise,
// MakeSyntheticPlantData) in a fresh database file under the temp folder.
//
// Printed:
//   1. ingestion as the daemon does it: one transaction per 5 s sample plus
//      an AggregateMinutes call after it (first day), then bulk ingestion of
//      the other 13 days (one transaction per hour of samples);
//   2. aggregation of the 13 bulk days in one call;
//   3. reading the 14-day window of 1-min rows into a Series (target
//      <= 0.5 s), and reading 14 days of 5 s samples and aggregating them;
//   4. forecasts as the daemon writes them: a 24 h forecast at 1 min issued
//      every hour for the 14 days; the time to write one issue, to read the
//      next 24 h of forecast_latest and to compute forecast_skill of 14 days;
//   5. database growth per day, from the pages in use after a checkpoint,
//      for the 5 s samples, the 1-min rows and the forecasts (before and
//      after PruneForecasts, which ApplyRetention runs).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/data/aggregate.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"
#include "io/store/store.h"

namespace pvtwin::cli {

namespace {

constexpr int kDays = 14;
constexpr double kPollS = 5.0;
constexpr std::size_t kSamplesPerHour = 720;

bool Check(bool ok, const std::string& error) {
  if (!ok) std::printf("  store error: %s\n", error.c_str());
  return ok;
}

// The bench's data and database, shared by its phases.
struct StoreBench {
  StoreBench(const Series& d, const std::vector<Sample>& s, Store& st, const StoreOptions& o)
      : data(d), samples(s), store(st), options(o) {}
  const Series& data;
  const std::vector<Sample>& samples;
  Store& store;
  StoreOptions options;
  int repeats = 1;
  std::int64_t begin_ts = 0, end_ts = 0;
  // Pages in use after a checkpoint: empty, with the samples, with the
  // 1-min rows, with the forecasts, after pruning them.
  std::int64_t empty_bytes = 0, samples_bytes = 0, all_bytes = 0, forecast_bytes = 0,
               pruned_bytes = 0;
  std::size_t forecast_issues = 0;
  double prune_s = 0.0;
  std::string error;
};

// 1. The first day as the daemon ingests it: one sample per transaction,
//    then AggregateMinutes up to the end of that poll period.
void IngestLikeTheDaemon(StoreBench& b, std::size_t day_samples) {
  std::vector<double> insert_s, aggregate_idle_s, aggregate_minute_s;
  for (std::size_t i = 0; i < day_samples; ++i) {
    auto start = std::chrono::steady_clock::now();
    if (!Check(b.store.InsertSamples({b.samples[i]}, &b.error), b.error)) break;
    insert_s.push_back(SecondsSince(start));
    start = std::chrono::steady_clock::now();
    int written = 0;
    if (!Check(b.store.AggregateMinutes(b.samples[i].ts_s + static_cast<std::int64_t>(kPollS),
                                        &written, &b.error),
               b.error)) {
      break;
    }
    (written > 0 ? aggregate_minute_s : aggregate_idle_s).push_back(SecondsSince(start));
  }
  const double per_poll_s =
      Median(insert_s) + Median(aggregate_idle_s) + Median(aggregate_minute_s) / (60.0 / kPollS);
  std::printf(
      "  daemon ingestion (day 1, %zu polls): insert 1 sample %.3f ms, AggregateMinutes"
      " %.3f ms (nothing due) / %.3f ms (one minute), medians\n",
      insert_s.size(), Median(insert_s) * 1e3, Median(aggregate_idle_s) * 1e3,
      Median(aggregate_minute_s) * 1e3);
  std::printf("    store work per 5 s poll: %.3f ms = %.4f %% of one core\n", per_poll_s * 1e3,
              100.0 * per_poll_s / kPollS);
}

// 2. The other days in bulk, then one aggregation of all their minutes.
void IngestInBulk(StoreBench& b, std::size_t day_samples) {
  auto start = std::chrono::steady_clock::now();
  for (std::size_t first = day_samples; first < b.samples.size(); first += kSamplesPerHour) {
    const std::size_t last = std::min(b.samples.size(), first + kSamplesPerHour);
    if (!Check(b.store.InsertSamples({b.samples.begin() + static_cast<std::ptrdiff_t>(first),
                                      b.samples.begin() + static_cast<std::ptrdiff_t>(last)},
                                     &b.error),
               b.error)) {
      break;
    }
  }
  const double bulk_s = SecondsSince(start);
  std::printf(
      "  bulk ingestion (days 2-%d, %zu samples, 1 h per transaction): %.2f s, %.1f us per"
      " sample\n",
      kDays, b.samples.size() - day_samples, bulk_s,
      bulk_s * 1e6 / static_cast<double>(b.samples.size() - day_samples));
  Check(b.store.Checkpoint(&b.samples_bytes, &b.error), b.error);
  start = std::chrono::steady_clock::now();
  int minutes = 0;
  Check(b.store.AggregateMinutes(b.end_ts, &minutes, &b.error), b.error);
  std::printf("  AggregateMinutes over days 2-%d: %d minutes in %.2f s\n", kDays, minutes,
              SecondsSince(start));
  Check(b.store.Checkpoint(&b.all_bytes, &b.error), b.error);
}

// 3. Reads of the 14-day window (the calibration's input).
void ReadTheWindow(StoreBench& b) {
  std::vector<double> read_minutes_s, read_raw_s, read_aggregate_s;
  std::size_t rows = 0;
  for (int r = 0; r < b.repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    Series window;
    if (!Check(b.store.ReadMinutes(b.begin_ts, b.end_ts, &window, &b.error), b.error)) break;
    read_minutes_s.push_back(SecondsSince(start));
    rows = window.size();
  }
  std::printf(
      "  read 14 days of 1-min rows into a Series (%zu rows): median %.1f ms of %d runs"
      " (target <= 500 ms)\n",
      rows, Median(read_minutes_s) * 1e3, b.repeats);
  const int heavy_repeats = std::max(1, std::min(b.repeats, 5));
  for (int r = 0; r < heavy_repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<Sample> raw;
    MinuteRows aggregated;
    if (!Check(b.store.ReadSamples(b.begin_ts, b.end_ts, &raw, &b.error), b.error)) break;
    read_raw_s.push_back(SecondsSince(start));
    if (!Check(AggregateSamples(raw, b.options.aggregate, &aggregated, &b.error), b.error)) break;
    read_aggregate_s.push_back(SecondsSince(start));
    rows = aggregated.rows.size();
  }
  std::printf(
      "  read 14 days of 5 s samples and aggregate them (%zu minutes): median %.1f ms"
      " (read %.1f ms) of %d runs\n",
      rows, Median(read_aggregate_s) * 1e3, Median(read_raw_s) * 1e3, heavy_repeats);
}

// 4. Hourly 24 h forecasts (the model's values do not matter here: the
//    measured outputs, scaled, stand in for them), their views, and pruning
//    as ApplyRetention does it, for all 14 days.
void ForecastsAndViews(StoreBench& b) {
  std::vector<double> issue_s;
  const std::int64_t horizon_s = 86400;
  for (std::int64_t issued = b.begin_ts; issued + horizon_s <= b.end_ts; issued += 3600) {
    std::vector<Store::ForecastRow> rows_24h;
    for (std::int64_t t = issued; t < issued + horizon_s; t += 60) {
      const auto i =
          static_cast<std::size_t>((t - b.begin_ts) / static_cast<std::int64_t>(kPollS));
      rows_24h.push_back({t, b.data[Channel::kPElW][i] * 1.05, b.data[Channel::kQThW][i] * 0.95,
                          b.data[Channel::kTPvC][i], b.data[Channel::kTOutC][i]});
    }
    const auto start = std::chrono::steady_clock::now();
    if (!Check(b.store.InsertForecast(issued, 1, "weather=weather_forecast", rows_24h, &b.error),
               b.error)) {
      break;
    }
    issue_s.push_back(SecondsSince(start));
  }
  b.forecast_issues = issue_s.size();
  Check(b.store.Checkpoint(&b.forecast_bytes, &b.error), b.error);
  std::vector<double> latest_s, skill_s;
  std::size_t skill_days = 0;
  for (int r = 0; r < b.repeats; ++r) {
    std::vector<Store::ForecastRow> latest;
    const auto start = std::chrono::steady_clock::now();
    if (!Check(b.store.ReadLatestForecast(b.end_ts - horizon_s, b.end_ts, &latest, &b.error),
               b.error)) {
      break;
    }
    latest_s.push_back(SecondsSince(start));
  }
  for (int r = 0; r < std::max(1, std::min(b.repeats, 5)); ++r) {
    std::vector<Store::SkillRow> skill;
    const auto start = std::chrono::steady_clock::now();
    if (!Check(b.store.ReadForecastSkill(b.begin_ts, b.end_ts, &skill, &b.error), b.error)) break;
    skill_s.push_back(SecondsSince(start));
    skill_days = skill.size();
  }
  std::printf(
      "  forecasts: %zu hourly issues of 1440 rows; write one issue %.1f ms, read 24 h of"
      " forecast_latest %.1f ms, forecast_skill of %zu days %.1f ms (medians)\n",
      issue_s.size(), Median(issue_s) * 1e3, Median(latest_s) * 1e3, skill_days,
      Median(skill_s) * 1e3);
  const auto start = std::chrono::steady_clock::now();
  Check(b.store.PruneForecasts(b.begin_ts, b.end_ts, &b.error), b.error);
  b.prune_s = SecondsSince(start);
  Check(b.store.Checkpoint(&b.pruned_bytes, &b.error), b.error);
}

// 5. Growth per day.
void PrintGrowth(const StoreBench& b) {
  const double mb = 1024.0 * 1024.0;
  const double issues_per_day =
      static_cast<double>(std::max<std::size_t>(1, b.forecast_issues)) / 24.0;
  const double raw_per_day = static_cast<double>(b.samples_bytes - b.empty_bytes) / kDays;
  const double minute_per_day = static_cast<double>(b.all_bytes - b.samples_bytes) / kDays;
  const double forecast_per_day =
      static_cast<double>(b.forecast_bytes - b.all_bytes) / issues_per_day;
  const double pruned_per_day = static_cast<double>(b.pruned_bytes - b.all_bytes) / issues_per_day;
  std::printf(
      "  database growth per day: 5 s samples %.2f MiB, 1-min rows %.2f MiB, hourly"
      " forecasts %.2f MiB (%.2f MiB once pruned; pruning 14 days took %.2f s)\n",
      raw_per_day / mb, minute_per_day / mb, forecast_per_day / mb, pruned_per_day / mb,
      b.prune_s);
  std::printf(
      "    steady state: %.0f MiB for 30 days of samples + %.0f MiB per year of 1-min rows"
      " and pruned forecasts\n",
      30 * (raw_per_day + forecast_per_day) / mb, 365 * (minute_per_day + pruned_per_day) / mb);
}

}  // namespace

void BenchStore(int repeats, std::uint64_t seed) {
  namespace fs = std::filesystem;
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = kDays;
  weather.step_s = kPollS;
  weather.seed = seed;
  ModelSpec spec;
  std::string error;
  ParseVariant("2N1Ccolwr", &spec, &error);
  const Series data = MakeSyntheticPlantData(plant, weather, spec, ReferenceTruthParams(plant),
                                             RealisticSensorNoise(seed));
  const std::vector<Sample> samples = SamplesFromSeries(data);

  const fs::path dir =
      fs::temp_directory_path() / ("pvtwin_bench_store_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "bench.db").string();
  std::printf("store: %d days of 5 s samples (%zu rows, %zu channels), weather seed %llu\n", kDays,
              samples.size(), kNumChannels, static_cast<unsigned long long>(seed));
  std::printf("  database %s (the temp folder's file system; an SD card is slower)\n",
              path.c_str());

  StoreOptions options;
  options.aggregate.sample_period_s = kPollS;
  options.aggregate.fluid_cp_j_kgk = plant.fluid_cp_j_kgk;
  std::unique_ptr<Store> store = Store::Open(path, options, &error);
  if (!Check(store != nullptr, error)) {
    fs::remove_all(dir);
    return;
  }
  StoreBench b(data, samples, *store, options);
  b.repeats = repeats;
  b.begin_ts = data.time_s.front();
  b.end_ts = data.time_s.back() + static_cast<std::int64_t>(kPollS);
  if (Check(store->Checkpoint(&b.empty_bytes, &b.error), b.error)) {
    const std::size_t day_samples = static_cast<std::size_t>(86400 / kPollS);
    IngestLikeTheDaemon(b, day_samples);
    IngestInBulk(b, day_samples);
    ReadTheWindow(b);
    ForecastsAndViews(b);
    PrintGrowth(b);
  }
  store.reset();
  fs::remove_all(dir);
}

}  // namespace pvtwin::cli
