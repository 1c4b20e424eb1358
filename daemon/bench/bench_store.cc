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
  const std::int64_t begin_ts = data.time_s.front();
  const std::int64_t end_ts = data.time_s.back() + static_cast<std::int64_t>(kPollS);

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
  std::int64_t empty_bytes = 0, samples_bytes = 0, all_bytes = 0, forecast_bytes = 0;
  if (!Check(store != nullptr, error) || !Check(store->Checkpoint(&empty_bytes, &error), error)) {
    fs::remove_all(dir);
    return;
  }

  // 1. The first day as the daemon ingests it: one sample per transaction,
  //    then AggregateMinutes up to the end of that poll period.
  const std::size_t day_samples = static_cast<std::size_t>(86400 / kPollS);
  std::vector<double> insert_s, aggregate_idle_s, aggregate_minute_s;
  for (std::size_t i = 0; i < day_samples; ++i) {
    auto start = std::chrono::steady_clock::now();
    if (!Check(store->InsertSamples({samples[i]}, &error), error)) break;
    insert_s.push_back(SecondsSince(start));
    start = std::chrono::steady_clock::now();
    int written = 0;
    if (!Check(store->AggregateMinutes(samples[i].ts_s + static_cast<std::int64_t>(kPollS),
                                       &written, &error),
               error)) {
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

  // 2. The other days in bulk, then one aggregation of all their minutes.
  auto start = std::chrono::steady_clock::now();
  for (std::size_t b = day_samples; b < samples.size(); b += kSamplesPerHour) {
    const std::size_t e = std::min(samples.size(), b + kSamplesPerHour);
    if (!Check(store->InsertSamples({samples.begin() + static_cast<std::ptrdiff_t>(b),
                                     samples.begin() + static_cast<std::ptrdiff_t>(e)},
                                    &error),
               error)) {
      break;
    }
  }
  const double bulk_s = SecondsSince(start);
  std::printf(
      "  bulk ingestion (days 2-%d, %zu samples, 1 h per transaction): %.2f s, %.1f us per"
      " sample\n",
      kDays, samples.size() - day_samples, bulk_s,
      bulk_s * 1e6 / static_cast<double>(samples.size() - day_samples));
  Check(store->Checkpoint(&samples_bytes, &error), error);
  start = std::chrono::steady_clock::now();
  int minutes = 0;
  Check(store->AggregateMinutes(end_ts, &minutes, &error), error);
  std::printf("  AggregateMinutes over days 2-%d: %d minutes in %.2f s\n", kDays, minutes,
              SecondsSince(start));
  Check(store->Checkpoint(&all_bytes, &error), error);

  // 3. Reads of the 14-day window (the calibration's input).
  std::vector<double> read_minutes_s, read_raw_s, read_aggregate_s;
  std::size_t rows = 0;
  for (int r = 0; r < repeats; ++r) {
    start = std::chrono::steady_clock::now();
    Series window;
    if (!Check(store->ReadMinutes(begin_ts, end_ts, &window, &error), error)) break;
    read_minutes_s.push_back(SecondsSince(start));
    rows = window.size();
  }
  std::printf(
      "  read 14 days of 1-min rows into a Series (%zu rows): median %.1f ms of %d runs"
      " (target <= 500 ms)\n",
      rows, Median(read_minutes_s) * 1e3, repeats);
  const int heavy_repeats = std::max(1, std::min(repeats, 5));
  for (int r = 0; r < heavy_repeats; ++r) {
    start = std::chrono::steady_clock::now();
    std::vector<Sample> raw;
    MinuteRows aggregated;
    if (!Check(store->ReadSamples(begin_ts, end_ts, &raw, &error), error)) break;
    read_raw_s.push_back(SecondsSince(start));
    if (!Check(AggregateSamples(raw, options.aggregate, &aggregated, &error), error)) break;
    read_aggregate_s.push_back(SecondsSince(start));
    rows = aggregated.rows.size();
  }
  std::printf(
      "  read 14 days of 5 s samples and aggregate them (%zu minutes): median %.1f ms"
      " (read %.1f ms) of %d runs\n",
      rows, Median(read_aggregate_s) * 1e3, Median(read_raw_s) * 1e3, heavy_repeats);

  // 4. Hourly 24 h forecasts (the model's values do not matter here: the
  //    measured outputs, scaled, stand in for them).
  std::vector<double> issue_s;
  const std::int64_t horizon_s = 86400;
  for (std::int64_t issued = begin_ts; issued + horizon_s <= end_ts; issued += 3600) {
    std::vector<Store::ForecastRow> rows_24h;
    for (std::int64_t t = issued; t < issued + horizon_s; t += 60) {
      const auto i = static_cast<std::size_t>((t - begin_ts) / static_cast<std::int64_t>(kPollS));
      rows_24h.push_back({t, data[Channel::kPElW][i] * 1.05, data[Channel::kQThW][i] * 0.95,
                          data[Channel::kTPvC][i], data[Channel::kTOutC][i]});
    }
    start = std::chrono::steady_clock::now();
    if (!Check(store->InsertForecast(issued, 1, "weather=weather_forecast", rows_24h, &error),
               error)) {
      break;
    }
    issue_s.push_back(SecondsSince(start));
  }
  Check(store->Checkpoint(&forecast_bytes, &error), error);
  std::vector<double> latest_s, skill_s;
  std::size_t skill_days = 0;
  for (int r = 0; r < repeats; ++r) {
    std::vector<Store::ForecastRow> latest;
    start = std::chrono::steady_clock::now();
    if (!Check(store->ReadLatestForecast(end_ts - horizon_s, end_ts, &latest, &error), error)) {
      break;
    }
    latest_s.push_back(SecondsSince(start));
  }
  for (int r = 0; r < heavy_repeats; ++r) {
    std::vector<Store::SkillRow> skill;
    start = std::chrono::steady_clock::now();
    if (!Check(store->ReadForecastSkill(begin_ts, end_ts, &skill, &error), error)) break;
    skill_s.push_back(SecondsSince(start));
    skill_days = skill.size();
  }
  std::printf(
      "  forecasts: %zu hourly issues of 1440 rows; write one issue %.1f ms, read 24 h of"
      " forecast_latest %.1f ms, forecast_skill of %zu days %.1f ms (medians)\n",
      issue_s.size(), Median(issue_s) * 1e3, Median(latest_s) * 1e3, skill_days,
      Median(skill_s) * 1e3);

  // Pruning as ApplyRetention does it, for all 14 days.
  std::int64_t pruned_bytes = 0;
  start = std::chrono::steady_clock::now();
  Check(store->PruneForecasts(begin_ts, end_ts, &error), error);
  const double prune_s = SecondsSince(start);
  Check(store->Checkpoint(&pruned_bytes, &error), error);

  // 5. Growth per day.
  const double mb = 1024.0 * 1024.0;
  const double issues_per_day =
      static_cast<double>(std::max<std::size_t>(1, issue_s.size())) / 24.0;
  const double raw_per_day = static_cast<double>(samples_bytes - empty_bytes) / kDays;
  const double minute_per_day = static_cast<double>(all_bytes - samples_bytes) / kDays;
  const double forecast_per_day = static_cast<double>(forecast_bytes - all_bytes) / issues_per_day;
  const double pruned_per_day = static_cast<double>(pruned_bytes - all_bytes) / issues_per_day;
  std::printf(
      "  database growth per day: 5 s samples %.2f MiB, 1-min rows %.2f MiB, hourly"
      " forecasts %.2f MiB (%.2f MiB once pruned; pruning 14 days took %.2f s)\n",
      raw_per_day / mb, minute_per_day / mb, forecast_per_day / mb, pruned_per_day / mb, prune_s);
  std::printf(
      "    steady state: %.0f MiB for 30 days of samples + %.0f MiB per year of 1-min rows"
      " and pruned forecasts\n",
      30 * (raw_per_day + forecast_per_day) / mb, 365 * (minute_per_day + pruned_per_day) / mb);
  store.reset();
  fs::remove_all(dir);
}

}  // namespace pvtwin::cli
