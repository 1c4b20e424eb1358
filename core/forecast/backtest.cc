#include "core/forecast/backtest.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <mutex>
#include <set>
#include <span>
#include <thread>
#include <utility>

#include "core/common/threads.h"
#include "core/common/units.h"
#include "core/data/resample.h"
#include "core/model/irradiance_drivers.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"

namespace pvtwin {

namespace {

std::string FormatNumber(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

bool IsDivisorOfDay(double step_s) {
  return std::isfinite(step_s) && step_s == std::floor(step_s) && step_s >= 1.0 &&
         std::fmod(86400.0, step_s) == 0.0;
}

struct Slice {
  Drivers drivers;
  Measurements meas;
};

// Drivers and measurements of rows [begin, end); `sun` holds the positions of
// every row of s. False with *error if the drivers cannot be built (not
// expected: the columns were checked up front).
bool PrepareSlice(const Series& s, std::span<const SolarPosition> sun, std::size_t begin,
                  std::size_t end, const Plant& plant, const ModelSpec& spec, Slice* out,
                  std::string* error) {
  if (begin >= end) {
    out->drivers = Drivers{};
    out->meas = Measurements{};
    return true;
  }
  const Series rows = s.Slice(begin, end);
  if (!PrepareDrivers(rows, plant, spec, sun.subspan(begin, end - begin), &out->drivers, error)) {
    return false;
  }
  out->meas = MakeMeasurements(rows, out->drivers);
  return true;
}

struct Job {
  std::size_t day = 0;
  std::size_t variant = 0;
  std::size_t train = 0;
};

// Each job its own work item.
std::vector<std::vector<std::size_t>> SingleJobs(std::size_t n) {
  std::vector<std::vector<std::size_t>> items(n);
  for (std::size_t j = 0; j < n; ++j) items[j] = {j};
  return items;
}

// One chain per variant and training length, its jobs in day order (the
// jobs are ordered by day). The variants with more free parameters, the
// longer fits, come first, so that the last chain to start is a short one.
std::vector<std::vector<std::size_t>> WarmStartChains(const std::vector<Job>& jobs,
                                                      const std::vector<ModelSpec>& specs) {
  std::vector<std::vector<std::size_t>> chains;
  std::vector<std::pair<std::size_t, std::size_t>> keys;  // (variant, train) of each chain
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const std::pair<std::size_t, std::size_t> key{jobs[j].variant, jobs[j].train};
    const auto at = std::find(keys.begin(), keys.end(), key);
    if (at == keys.end()) {
      keys.push_back(key);
      chains.push_back({j});
    } else {
      chains[static_cast<std::size_t>(at - keys.begin())].push_back(j);
    }
  }
  std::vector<std::size_t> order(chains.size());
  for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return DefaultFreeParams(specs[keys[a].first]).count() >
           DefaultFreeParams(specs[keys[b].first]).count();
  });
  std::vector<std::vector<std::size_t>> sorted;
  for (const std::size_t c : order) sorted.push_back(std::move(chains[c]));
  return sorted;
}

// Start of the n-th solar day with data before day_start_s (data_days:
// sorted starts of the days that hold rows); n calendar days before it when
// fewer days with data precede it.
std::int64_t TrainingStartS(const std::vector<std::int64_t>& data_days, std::int64_t day_start_s,
                            int n) {
  const auto before = std::lower_bound(data_days.begin(), data_days.end(), day_start_s);
  if (before - data_days.begin() >= n) return *(before - n);
  return day_start_s - static_cast<std::int64_t>(n) * kSecondsPerDay;
}

// Sorted starts of the solar days whose rows reach across solar noon (at
// least one row before it and one at or after it): a measured day, whole or
// ending at sunset, not an hour of night at the end of a file.
std::vector<std::int64_t> DaysWithData(const Series& s, std::int64_t offset_s) {
  constexpr std::int64_t kNoonS = kSecondsPerDay / 2;
  std::vector<std::int64_t> days;
  std::int64_t day = 0;
  bool morning = false, afternoon = false;
  const auto close_day = [&] {
    if (morning && afternoon) days.push_back(day);
  };
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int64_t d = SolarDayStartS(s.time_s[i], offset_s);
    if (i == 0 || d != day) {
      if (i > 0) close_day();
      day = d;
      morning = afternoon = false;
    }
    (s.time_s[i] < d + kNoonS ? morning : afternoon) = true;
  }
  if (s.size() > 0) close_day();
  return days;
}

// `warm`: the start is the day before's fit (BacktestOptions::warm_start),
// which the identification's day subset stage would only move away from
// (IdentOptions::day_subset_stage).
void RunJob(const Series& s, std::span<const SolarPosition> sun, const Plant& plant,
            const BacktestOptions& options, const ModelSpec& spec, const ParamVector& start,
            bool warm, std::int64_t day_start_s, std::int64_t solar_offset_s,
            const std::vector<std::int64_t>& data_days, BacktestDay* out) {
  const std::int64_t day_end_s = day_start_s + kSecondsPerDay;
  const std::int64_t train_start_s = TrainingStartS(data_days, day_start_s, out->train_days);
  const std::size_t min_rows = static_cast<std::size_t>(std::max(options.ident.min_rows, 0));
  std::string error;

  Slice test;
  if (!PrepareSlice(s, sun, s.RowAtOrAfter(day_start_s), s.RowAtOrAfter(day_end_s), plant, spec,
                    &test, &error)) {
    out->failure = BacktestFailure::kTooLittleData;
    out->failure_reason = "test day " + SolarDate(day_start_s, solar_offset_s) + ": " + error;
    return;
  }
  if (test.meas.rows.size() < min_rows) {
    out->failure = BacktestFailure::kTooLittleData;
    out->failure_reason =
        "test day " + SolarDate(day_start_s, solar_offset_s) + " has " +
        std::to_string(test.meas.rows.size()) +
        " objective rows, fewer than ident.min_rows = " + std::to_string(options.ident.min_rows);
    return;
  }
  Slice train;
  const std::string window = "training window " + SolarDate(train_start_s, solar_offset_s) + " … " +
                             SolarDate(day_start_s - 1, solar_offset_s) + " (" +
                             std::to_string(out->train_days) + " days with data)";
  if (!PrepareSlice(s, sun, s.RowAtOrAfter(train_start_s), s.RowAtOrAfter(day_start_s), plant, spec,
                    &train, &error)) {
    out->failure = BacktestFailure::kTooLittleData;
    out->failure_reason = window + ": " + error;
    return;
  }
  if (train.meas.rows.size() < min_rows) {
    out->failure = BacktestFailure::kTooLittleData;
    out->failure_reason =
        window + " has " + std::to_string(train.meas.rows.size()) +
        " objective rows, fewer than ident.min_rows = " + std::to_string(options.ident.min_rows);
    return;
  }

  IdentOptions ident = options.ident;
  if (warm) ident.day_subset_stage = false;
  const IdentSummary summary = Identify(train.drivers, train.meas, start, ident);
  out->runtime_s = summary.runtime_s;
  out->coarse_runtime_s = summary.coarse_runtime_s;
  out->fixing_runtime_s = summary.fixing_runtime_s;
  out->coarse_subset_runtime_s = summary.coarse_subset_runtime_s;
  out->trial_runtime_s = summary.trial_runtime_s;
  out->evaluations = summary.evaluations;
  out->params = summary.params;
  if (!summary.ok) {
    out->failure = BacktestFailure::kIdentification;
    out->failure_reason = "identification failed: " + summary.failure_reason;
    return;
  }

  SimOutputs sim;
  Simulate(test.drivers, summary.params, &sim);
  out->test = ComputeErrors(test.meas, sim, plant.area_m2);
  if (!std::isfinite(out->test.mae_p_el_w_m2) || !std::isfinite(out->test.mae_q_th_w_m2)) {
    out->failure = BacktestFailure::kNonFiniteErrors;
    out->failure_reason = "the identified model gives non-finite outputs on the test day";
    return;
  }
  out->ok = true;
}

BacktestAverage Average(const std::vector<BacktestDay>& days, const std::string& variant,
                        int train_days) {
  BacktestAverage avg;
  avg.variant = variant;
  avg.train_days = train_days;
  double sum_p = 0.0, sum_q = 0.0, sum_runtime = 0.0;
  double sum_np = 0.0, sum_nq = 0.0;
  int count_np = 0, count_nq = 0;
  for (const BacktestDay& d : days) {
    if (d.variant != variant || d.train_days != train_days) continue;
    if (!d.ok) {
      ++avg.days_failed;
      continue;
    }
    ++avg.days_ok;
    sum_p += d.test.mae_p_el_w_m2;
    sum_q += d.test.mae_q_th_w_m2;
    sum_runtime += d.runtime_s;
    if (std::isfinite(d.test.nmae_p_el)) {
      sum_np += d.test.nmae_p_el;
      ++count_np;
    }
    if (std::isfinite(d.test.nmae_q_th)) {
      sum_nq += d.test.nmae_q_th;
      ++count_nq;
    }
  }
  const double nan = std::nan("");
  const double n = avg.days_ok;
  avg.mae_p_el_w_m2 = avg.days_ok > 0 ? sum_p / n : nan;
  avg.mae_q_th_w_m2 = avg.days_ok > 0 ? sum_q / n : nan;
  avg.runtime_s = avg.days_ok > 0 ? sum_runtime / n : nan;
  avg.nmae_p_el = count_np > 0 ? sum_np / count_np : nan;
  avg.nmae_q_th = count_nq > 0 ? sum_nq / count_nq : nan;
  return avg;
}

// ---------------------------------------------------------------------------
// Text tables.

// Display width of UTF-8 text (code points; every character used here is one
// column wide).
std::size_t Width(const std::string& text) {
  std::size_t w = 0;
  for (unsigned char c : text) w += (c & 0xC0) != 0x80;
  return w;
}

std::string PadLeft(const std::string& text, std::size_t width) {
  const std::size_t w = Width(text);
  return w >= width ? text : std::string(width - w, ' ') + text;
}

std::string PadRight(const std::string& text, std::size_t width) {
  const std::size_t w = Width(text);
  return w >= width ? text : text + std::string(width - w, ' ');
}

std::string Fixed(double x, int decimals) {
  if (!std::isfinite(x)) return "-";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
  return buf;
}

// A table of left-aligned first column and right-aligned other columns.
std::string RenderTable(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> widths;
  for (const auto& row : rows) {
    if (widths.size() < row.size()) widths.resize(row.size(), 0);
    for (std::size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], Width(row[c]));
  }
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (c > 0) line += "  ";
      line += c == 0 ? PadRight(row[c], widths[c]) : PadLeft(row[c], widths[c]);
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += "  " + line + "\n";
  }
  return out;
}

std::string StepLabel(double step_s) {
  if (step_s >= 60.0 && std::fmod(step_s, 60.0) == 0.0) return FormatNumber(step_s / 60.0) + " min";
  return FormatNumber(step_s) + " s";
}

}  // namespace

std::string_view ToString(BacktestFailure failure) {
  switch (failure) {
    case BacktestFailure::kNone:
      return "none";
    case BacktestFailure::kTooLittleData:
      return "too_little_data";
    case BacktestFailure::kIdentification:
      return "identification";
    case BacktestFailure::kNonFiniteErrors:
      return "non_finite_errors";
  }
  return "unknown";
}

bool BacktestOptions::IsValid(std::string* why) const {
  std::vector<std::string> problems;
  if (variants.empty()) problems.push_back("variants = (none): give at least one variant");
  std::set<std::string> seen;
  for (const std::string& name : variants) {
    ModelSpec spec;
    std::string error;
    if (!ParseVariant(name, &spec, &error)) {
      problems.push_back("variants = " + name + ": " + error);
    } else if (!seen.insert(name).second) {
      problems.push_back("variants = " + name + ": listed twice");
    }
  }
  if (train_days.empty()) problems.push_back("train_days = (none): give at least one value");
  std::set<int> seen_n;
  for (int n : train_days) {
    if (n < 1 || n > 365) {
      problems.push_back("train_days = " + std::to_string(n) + ": must be within [1, 365]");
    } else if (!seen_n.insert(n).second) {
      problems.push_back("train_days = " + std::to_string(n) + ": listed twice");
    }
  }
  if (!(step_s >= 5.0 && step_s <= 900.0) || !IsDivisorOfDay(step_s)) {
    problems.push_back("step_s = " + FormatNumber(step_s) +
                       ": must be whole seconds within [5, 900] dividing 86400");
  }
  if (test_days < 1) {
    problems.push_back("test_days = " + std::to_string(test_days) + ": must be >= 1");
  }
  if (threads < 0) {
    problems.push_back("threads = " + std::to_string(threads) + ": must be >= 0 (0 = all cores)");
  }
  std::string ident_why;
  if (!ident.IsValid(&ident_why)) problems.push_back("ident." + ident_why);
  if (problems.empty()) return true;
  if (why != nullptr) {
    why->clear();
    for (const std::string& p : problems) *why += (why->empty() ? "" : "; ") + p;
  }
  return false;
}

bool RunBacktest(const Series& data, const Plant& plant, const BacktestOptions& options,
                 BacktestResult* result, std::string* error,
                 const std::function<void(int, int, const BacktestDay&)>& progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  if (!options.IsValid(error)) return false;
  if (data.size() == 0) {
    *error = "no data rows";
    return false;
  }
  if (data.size() < 2 || !(data.step_s > 0.0)) {
    *error = "cannot tell the data step from " + std::to_string(data.size()) + " row(s)";
    return false;
  }

  // The series at the requested step.
  Series resampled;
  const Series* series = &data;
  if (options.step_s < data.step_s) {
    *error = "step_s = " + FormatNumber(options.step_s) + ": finer than the data step " +
             FormatNumber(data.step_s) + " s";
    return false;
  }
  if (options.step_s > data.step_s) {
    std::string why;
    if (!Resample(data, options.step_s, &resampled, &why)) {
      *error = "step_s = " + FormatNumber(options.step_s) + ": " + why;
      return false;
    }
    series = &resampled;
  }
  const Series& s = *series;

  // Variants, and their columns, checked up front.
  std::vector<ModelSpec> specs(options.variants.size());
  std::string missing;
  const Series first_row = s.Slice(0, 1);
  for (std::size_t v = 0; v < specs.size(); ++v) {
    std::string why;
    ParseVariant(options.variants[v], &specs[v], &why);  // checked by IsValid
    Drivers drivers;
    if (!PrepareDrivers(first_row, plant, specs[v], &drivers, &why)) {
      missing += (missing.empty() ? "" : "\n") + why;
    }
  }
  if (!missing.empty()) {
    *error = missing;
    return false;
  }

  // Test days.
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  const int max_n = *std::max_element(options.train_days.begin(), options.train_days.end());
  const std::vector<std::int64_t> data_days = DaysWithData(s, offset_s);
  const std::int64_t data_end_s = s.time_s.back() + static_cast<std::int64_t>(s.step_s);
  std::int64_t first_day_s = 0;
  if (options.first_test_day_s) {
    first_day_s = SolarDayStartS(*options.first_test_day_s, offset_s);
  } else if (data_days.size() > static_cast<std::size_t>(max_n)) {
    first_day_s = data_days[static_cast<std::size_t>(max_n)];
  } else {
    *error = "no test day in the data: they hold " + std::to_string(data_days.size()) +
             " solar day(s) with data, from " + SolarDate(s.time_s.front(), offset_s) + " to " +
             SolarDate(data_end_s - 1, offset_s) + "; " + std::to_string(max_n) +
             " training days + 1 test day are needed";
    return false;
  }
  std::vector<std::int64_t> day_starts;
  int skipped_days = 0;
  for (int k = 0; k < options.test_days; ++k) {
    const std::int64_t d = first_day_s + k * kSecondsPerDay;
    if (d >= data_end_s) break;
    if (std::binary_search(data_days.begin(), data_days.end(), d)) {
      day_starts.push_back(d);
    } else {
      ++skipped_days;
    }
  }
  if (day_starts.empty()) {
    *error = "no test day with data: the data run from " + SolarDate(s.time_s.front(), offset_s) +
             " to " + SolarDate(data_end_s - 1, offset_s) +
             " (local solar days), the first test day is " + SolarDate(first_day_s, offset_s);
    return false;
  }

  // Jobs, in the order of the result.
  const std::size_t n_variants = specs.size();
  const std::size_t n_train = options.train_days.size();
  std::vector<Job> jobs;
  jobs.reserve(day_starts.size() * n_variants * n_train);
  for (std::size_t d = 0; d < day_starts.size(); ++d) {
    for (std::size_t v = 0; v < n_variants; ++v) {
      for (std::size_t k = 0; k < n_train; ++k) jobs.push_back({d, v, k});
    }
  }
  std::vector<BacktestDay> days(jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    days[j].day_start_s = day_starts[jobs[j].day];
    days[j].variant = options.variants[jobs[j].variant];
    days[j].train_days = options.train_days[jobs[j].train];
  }

  // The work items: each job alone, or with warm starts one chain per
  // variant and training length, its days in order.
  const std::vector<std::vector<std::size_t>> chains =
      options.warm_start ? WarmStartChains(jobs, specs) : SingleJobs(jobs.size());
  const ParamVector table3 = StartParams(plant);
  // The sun at every row once: each job's slices take their part of it
  // instead of computing it again per variant and window.
  const std::vector<SolarPosition> sun = SunAtRowMiddles(s, plant);
  std::atomic<std::size_t> next{0};
  std::mutex progress_mutex;
  int done = 0;
  const int total = static_cast<int>(jobs.size());
  auto worker = [&]() {
    for (std::size_t c = next.fetch_add(1); c < chains.size(); c = next.fetch_add(1)) {
      const BacktestDay* before = nullptr;
      for (const std::size_t j : chains[c]) {
        const bool warm = before != nullptr && before->ok;
        const ParamVector& start = warm ? before->params : table3;
        RunJob(s, sun, plant, options, specs[jobs[j].variant], start, warm, days[j].day_start_s,
               offset_s, data_days, &days[j]);
        before = &days[j];
        std::lock_guard<std::mutex> lock(progress_mutex);
        ++done;
        if (progress) progress(done, total, days[j]);
      }
    }
  };
  const unsigned threads = options.threads > 0 ? static_cast<unsigned>(options.threads)
                                               : std::max(1u, std::thread::hardware_concurrency());
  RunOnThreads(std::min<unsigned>(threads, static_cast<unsigned>(chains.size())), worker);

  BacktestResult out;
  out.days = std::move(days);
  for (const std::string& variant : options.variants) {
    for (int n : options.train_days) out.averages.push_back(Average(out.days, variant, n));
  }
  out.step_s = s.step_s;
  out.solar_offset_s = offset_s;
  out.test_days = static_cast<int>(day_starts.size());
  out.skipped_days = skipped_days;
  out.warm_start = options.warm_start;
  out.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  *result = std::move(out);
  return true;
}

std::string FormatBacktestTables(const BacktestResult& result) {
  std::vector<std::int64_t> day_starts;
  for (const BacktestDay& d : result.days) {
    if (day_starts.empty() || day_starts.back() < d.day_start_s)
      day_starts.push_back(d.day_start_s);
  }
  std::vector<int> train_days;
  std::vector<std::string> variants;
  for (const BacktestAverage& a : result.averages) {
    if (std::find(train_days.begin(), train_days.end(), a.train_days) == train_days.end()) {
      train_days.push_back(a.train_days);
    }
    if (std::find(variants.begin(), variants.end(), a.variant) == variants.end()) {
      variants.push_back(a.variant);
    }
  }
  std::string out;
  out += "Backtest: " + std::to_string(day_starts.size()) + " test day(s)";
  if (!day_starts.empty()) {
    out += " " + SolarDate(day_starts.front(), result.solar_offset_s) + " … " +
           SolarDate(day_starts.back(), result.solar_offset_s) + " (local mean solar days)";
  }
  out += ", time step " + StepLabel(result.step_s) + ", wall time " + Fixed(result.wall_time_s, 1) +
         " s\n";
  out +=
      "Each test day is predicted by a model identified on the n days with data before it; means "
      "over "
      "the days identified.\n";
  if (result.warm_start) {
    out +=
        "Warm starts: each variant's identification starts from its parameters of the day "
        "before (the first day, and a day after a failed one, from Table 3).\n";
  }
  out += "\n";

  // Table 6 shape.
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"variant", "n (days)", "MAE_Qu (W/m²)", "MAE_Pel (W/m²)", "nMAE_Qu (%)",
                  "nMAE_Pel (%)", "runtime (s)", "days ok", "failed"});
  for (const BacktestAverage& a : result.averages) {
    rows.push_back({a.variant, std::to_string(a.train_days), Fixed(a.mae_q_th_w_m2, 1),
                    Fixed(a.mae_p_el_w_m2, 2), Fixed(100.0 * a.nmae_q_th, 1),
                    Fixed(100.0 * a.nmae_p_el, 2), Fixed(a.runtime_s, 2), std::to_string(a.days_ok),
                    std::to_string(a.days_failed)});
  }
  out += "Model variants (shape of the paper's Table 6):\n" + RenderTable(rows);

  // Table 4 shape, per variant.
  if (train_days.size() > 1) {
    for (const std::string& variant : variants) {
      std::vector<std::vector<std::string>> t4(5);
      t4[0].push_back("training period (days)");
      t4[1].push_back("mean calibration runtime (s)");
      t4[2].push_back("mean MAE_Pel (W/m²)");
      t4[3].push_back("mean MAE_Qu (W/m²)");
      t4[4].push_back("days ok / failed");
      for (int n : train_days) {
        auto it = std::find_if(
            result.averages.begin(), result.averages.end(),
            [&](const BacktestAverage& a) { return a.variant == variant && a.train_days == n; });
        if (it == result.averages.end()) continue;
        t4[0].push_back(std::to_string(n));
        t4[1].push_back(Fixed(it->runtime_s, 2));
        t4[2].push_back(Fixed(it->mae_p_el_w_m2, 2));
        t4[3].push_back(Fixed(it->mae_q_th_w_m2, 1));
        t4[4].push_back(std::to_string(it->days_ok) + " / " + std::to_string(it->days_failed));
      }
      out += "\n" + variant + " by training period (shape of the paper's Table 4):\n" +
             RenderTable(t4);
    }
  }

  // Stability of the identified parameters over the test days: the paper
  // saw U_front spread over three decades (its Fig. 8).
  for (const BacktestAverage& a : result.averages) {
    ModelSpec spec;
    std::string error;
    if (!ParseVariant(a.variant, &spec, &error) || a.days_ok < 2) continue;
    const auto used = UsedParams(spec);
    std::vector<std::vector<std::string>> t(1);
    t[0] = {"parameter", "unit", "median", "min", "max", "max/min"};
    for (std::size_t i = 0; i < kNumParams; ++i) {
      if (!used.test(i)) continue;
      std::vector<double> v;
      for (const BacktestDay& d : result.days) {
        if (d.ok && d.variant == a.variant && d.train_days == a.train_days)
          v.push_back(d.params[i]);
      }
      std::sort(v.begin(), v.end());
      if (v.empty() || v.front() == v.back()) continue;  // fixed
      const double median = v[v.size() / 2];
      t.push_back({std::string(kParamTable[i].name), std::string(kParamTable[i].unit),
                   FormatNumber(median), FormatNumber(v.front()), FormatNumber(v.back()),
                   v.front() > 0.0 ? Fixed(v.back() / v.front(), 2) : "-"});
    }
    if (t.size() > 1) {
      out += "\n" + a.variant + " n=" + std::to_string(a.train_days) +
             ": identified parameters over the test days\n" + RenderTable(t);
    }
  }

  // Failed jobs, one line each.
  bool header = false;
  for (const BacktestDay& d : result.days) {
    if (d.ok) continue;
    if (!header) out += "\nFailed days (left out of the means):\n";
    header = true;
    out += "  " + SolarDate(d.day_start_s, result.solar_offset_s) + " " + d.variant +
           " n=" + std::to_string(d.train_days) + ": " + d.failure_reason + "\n";
  }
  return out;
}

std::string FormatStepTable(std::span<const BacktestResult> runs) {
  std::vector<std::pair<std::string, int>> keys;
  for (const BacktestResult& r : runs) {
    for (const BacktestAverage& a : r.averages) {
      const std::pair<std::string, int> key{a.variant, a.train_days};
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    }
  }
  std::string out = "Time step of the data (shape of the paper's Table 5):\n";
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> head = {"time step"};
  for (const BacktestResult& r : runs) head.push_back(StepLabel(r.step_s));
  rows.push_back(head);
  for (const auto& key : keys) {
    const std::string& variant = key.first;  // named: clang 14 cannot capture a binding
    const int n = key.second;
    std::vector<std::string> runtime = {variant + " n=" + std::to_string(n) +
                                        ": calibration runtime (s)"};
    std::vector<std::string> mae_q = {"  mean MAE_Qu (W/m²)"};
    std::vector<std::string> mae_p = {"  mean MAE_Pel (W/m²)"};
    for (const BacktestResult& r : runs) {
      auto it = std::find_if(r.averages.begin(), r.averages.end(), [&](const BacktestAverage& a) {
        return a.variant == variant && a.train_days == n;
      });
      const bool found = it != r.averages.end();
      runtime.push_back(found ? Fixed(it->runtime_s, 2) : "-");
      mae_q.push_back(found ? Fixed(it->mae_q_th_w_m2, 1) : "-");
      mae_p.push_back(found ? Fixed(it->mae_p_el_w_m2, 2) : "-");
    }
    rows.push_back(runtime);
    rows.push_back(mae_q);
    rows.push_back(mae_p);
  }
  return out + RenderTable(rows);
}

}  // namespace pvtwin
