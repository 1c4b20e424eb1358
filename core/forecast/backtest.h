// The paper's rolling evaluation (section 3.3, Tables 4, 5 and 6): for each
// test day d and each (variant, n), identify the parameters on the n days
// before d, then simulate day d alone from its measured inputs with those
// parameters and score the prediction against what was measured on d.
//
// Days are local mean solar days: a day starts at local mean solar midnight,
// i.e. at 00:00 UTC shifted by −λ/15° hours (λ = plant longitude, east
// positive; rounded to the second). A day boundary then falls at night at any
// longitude, so no day cuts through a period of production. This is the day
// convention of the weather generator (DayTypesFor). A day is labelled by the
// calendar date of local mean solar time, e.g. at 16.128° E the day
// "2024-06-15" runs from 2024-06-14 22:55:29 UTC to 2024-06-15 22:55:29 UTC.
// A row belongs to the day that contains its time stamp (the start of its
// interval).
//
// Protocol of one job (test day d, variant v, n training days):
//   1. training rows: the n most recent solar days with data before d (in
//      data without gaps: time in [d − n·86400 s, d); in a set of separate
//      measured days, such as test-bench days, the n measured days before
//      d); test rows: time in [d, d + 86400 s). Each slice gets its own drivers (PrepareDrivers)
//      and measurements (MakeMeasurements); the model starts from the steady state of the first row
//      of each slice (paper 2.2).
//   2. Fewer than ident.min_rows objective rows in the test day or in the
//      training window: the job fails (BacktestFailure::kTooLittleData).
//   3. Identify(training) from StartParams(plant). summary.ok false: the job
//      fails (kIdentification) with the summary's reason.
//   4. Simulate the test day with the identified parameters; ComputeErrors on
//      its objective rows with the nameplate area plant.area_m2.
// Failed jobs are kept in BacktestResult::days and counted, but left out of
// the averages.
//
// Days with data: solar days whose rows reach across solar noon (a whole
// day, or one that ends at sunset; not an hour of night at a file's end).
// Test days: of options.test_days consecutive days from the first test day,
// those with data; the others are skipped (counted in
// BacktestResult::skipped_days). Default first test day: the
// (max(train_days) + 1)-th day with data, so that every training window holds
// max(train_days) days of data.
//
// Averages (paper: "averaged over the 29 test days"): MAE and runtime are the
// means over the successful days; nMAE is computed per day (day MAE / mean
// |measured| over that day, ComputeErrors) and then averaged over the
// successful days on which it is finite (a day without any measured heat has
// no nMAE of Q_u).
//
// Time step: the data are averaged (core/data/resample.h) onto options.step_s when
// that is coarser than the data's own step; a step finer than the data's, or
// not a whole multiple of it, is an error.
//
// Threads: the jobs are independent; `threads` workers (the calling thread is
// one of them) take the next job from a shared atomic index. The results do
// not depend on the number of threads: each job writes its own slot, and the
// order of BacktestResult::days is fixed (see there).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/common/calendar.h"
#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/fit/identification.h"

namespace pvtwin {

struct BacktestOptions {
  // Model variants (variant.h grammar), e.g. PaperVariants(). At least one,
  // no duplicates.
  std::vector<std::string> variants;
  // n: identify on the n days before the test day. Each 1 … 365, at least one,
  // no duplicates. The paper: 7, 14, 21, 28 (Table 4), 14 elsewhere.
  std::vector<int> train_days = {14};
  // Data step used, s: whole seconds in [5, 900] dividing 86400 (paper Table
  // 5: 5 s, 1, 5, 10, 15 min). The input is averaged onto it if coarser.
  double step_s = 60;
  // A time in the first test day (unix s); the test days start at the start
  // of its local solar day. Default: see the file comment.
  std::optional<std::int64_t> first_test_day_s;
  // Consecutive test days, ≥ 1; those without data are skipped, and fewer
  // are run if the data end before.
  int test_days = 29;
  // Identification options of every job (must be valid).
  IdentOptions ident;
  // Worker threads, ≥ 0; 0 = std::thread::hardware_concurrency().
  int threads = 0;
  // False: every identification starts from Table 3 (StartParams), each job
  // on its own. True: as the daemon re-identifies nightly (paper 3.3), each
  // variant and training length starts its first test day from Table 3 and
  // every next day from the parameters identified the day before (Table 3
  // again after a failed day). The days of one variant then run in order,
  // variants in parallel; the results do not depend on the thread count.
  bool warm_start = false;

  // False if a field is out of range; *why (if not null) then lists every
  // problem as "field = value: rule", separated by "; ".
  bool IsValid(std::string* why) const;
};

enum class BacktestFailure {
  kNone,
  kTooLittleData,    // test day or training window below ident.min_rows
  kIdentification,   // IdentSummary::ok false
  kNonFiniteErrors,  // the identified model gives NaN on the test day
};

// "none", "too_little_data", "identification", "non_finite_errors".
std::string_view ToString(BacktestFailure failure);

// One job: a test day, a variant, a training period.
struct BacktestDay {
  std::int64_t day_start_s = 0;  // start of the test day (unix s)
  std::string variant;           // as given in the options
  int train_days = 0;            // n
  bool ok = false;
  BacktestFailure failure = BacktestFailure::kNone;
  std::string failure_reason;            // when !ok
  ErrorMetrics test;                     // errors on the test day (when ok)
  double runtime_s = 0.0;                // calibration runtime (IdentSummary::runtime_s)
  double coarse_runtime_s = 0.0;         // its coarse stage (IdentSummary::coarse_runtime_s)
  double fixing_runtime_s = 0.0;         // its identifiability (IdentSummary::fixing_runtime_s)
  double coarse_subset_runtime_s = 0.0;  // IdentSummary::coarse_subset_runtime_s
  double trial_runtime_s = 0.0;          // IdentSummary::trial_runtime_s
  int evaluations = 0;                   // model simulations of the identification
  ParamVector params{};                  // identified parameters (when identification ran)
};

// Means over the test days of one (variant, n).
struct BacktestAverage {
  std::string variant;
  int train_days = 0;
  int days_ok = 0;
  int days_failed = 0;
  double mae_p_el_w_m2 = 0.0;  // NaN when no day succeeded
  double mae_q_th_w_m2 = 0.0;
  double nmae_p_el = 0.0;  // fraction (not %), mean of the per-day nMAE
  double nmae_q_th = 0.0;
  double runtime_s = 0.0;  // mean calibration runtime
};

struct BacktestResult {
  // Jobs ordered by test day, then variant (options order), then n (options
  // order): days[(day · variants + v) · train_days + k].
  std::vector<BacktestDay> days;
  // One per (variant, n), variant-major, in options order.
  std::vector<BacktestAverage> averages;
  double wall_time_s = 0.0;
  double step_s = 0.0;              // the step used
  std::int64_t solar_offset_s = 0;  // SolarDayOffsetS of the plant (labels the days)
  int test_days = 0;                // number of test days evaluated
  int skipped_days = 0;             // days of the range without data across solar noon
  bool warm_start = false;          // BacktestOptions::warm_start of the run
};

// Runs the backtest. Returns false with *error (nothing in *result) when the
// whole run cannot be done: invalid options, no data, a step finer than the
// data or not a multiple of it, a variant whose columns are missing
// (PrepareDrivers' message, one per variant), or no complete test day in the
// data. A job that fails is a failed day in *result, not an error.
// progress(done, total, day) is called once per finished job, from worker
// threads, one call at a time (under a mutex); it may be empty.
bool RunBacktest(const Series& data, const Plant& plant, const BacktestOptions& options,
                 BacktestResult* result, std::string* error,
                 const std::function<void(int, int, const BacktestDay&)>& progress = {});

// Text tables: the test days and step; a Table 6-shaped table (one row per
// variant and n: MAE_Qu, MAE_Pel in W/m², nMAE_Qu, nMAE_Pel in %, runtime in
// s, days ok/failed); and, when several n were run, a Table 4-shaped table per
// variant (training days as columns).
std::string FormatBacktestTables(const BacktestResult& result);

// A Table 5-shaped table: one column per run (time step), rows runtime,
// MAE_Qu, MAE_Pel for each (variant, n). The runs should share variants and
// training periods; a (variant, n) missing from a run shows "-".
std::string FormatStepTable(std::span<const BacktestResult> runs);

}  // namespace pvtwin
