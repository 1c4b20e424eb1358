// The coarse stage of identification: the free parameters (FreeSet), the
// data averaged to a coarser step (Coarsen), the fits on them from the start,
// from a day subset's optimum and from starts read off the residuals, and
// the pick of the fine stage's start among them. Internal to core/fit/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/fit/objective.h"

namespace pvtwin::fit_internal {

// Averages groups of `factor` consecutive rows of drivers and measurements
// (never across a restart, an unusable row or a pump start or stop), as
// resampling the data to a coarser step would. Used for the coarse first
// stage of identification. A group that mixed minutes with and without flow
// would have a mean flow the collector never saw, and the fluid conductance
// 2w/(r1 + 2w·r0) is far from linear in w: that bias moved the coarse
// optimum along the r0_fluid/r1_fluid valley, and the fine stage spent two
// thirds of its runs walking back.
// With `keep` (one flag per row of d), the rows not kept are left out: each
// stretch of them becomes one group that is not usable and not in the
// objective (the model restarts after it, as after a gap in the data).
void Coarsen(const Drivers& d, const Measurements& m, int factor, Drivers* cd, Measurements* cm,
             const std::vector<std::uint8_t>* keep = nullptr);

// The parameters a fit frees: used by the variant, requested (or free by
// default), with a non-empty range; `base` is the start clamped into the
// bounds.
struct FreeSet {
  ParamVector base{};
  std::vector<Param> free;
  std::vector<ParamInfo> infos;  // resolved, per free parameter
};

FreeSet SelectFree(const Drivers& drivers, const ParamVector& start, const IdentOptions& options);

// Starts for a second coarse fit, one per effect of the spec whose module
// reads a start from the residuals of the model without it
// (EffectModule::start_from_residuals) and whose parameters are free: that
// start at `at` (the first coarse optimum) with the effect removed. A local
// fit does not find such an effect's geometry from an arbitrary start (the
// shading obstacle: it only moves an obstacle whose window the sun already
// crosses, and where the fit ends depended on its path).
std::vector<ParamVector> RestartsFromResiduals(const Drivers& drivers, const Measurements& meas,
                                               const FreeSet& fs, const ParamVector& at);

// Coarse stage: the same fit on the data averaged to about 5 min gets close
// to the optimum at a fraction of the cost; the fine stage starts from there.
// (The model at 5 min is the same model: its exact step makes the coarse
// optimum close to the fine one.) CoarseFits fits on the coarsened data
// only, without the fine objective, so that it can run beside the start's
// cost on the data as given; PickCoarse then compares on those data.
struct CoarseFits {
  std::vector<IdentSummary> fits;  // the first from the start, then the restarts
  int simulations = 0;
  int sensitivity_runs = 0;
  int served_runs = 0;
  // The first fit, with the day subset's before it, at least halved the
  // cost of its start.
  bool far = false;
  // The days of the subset whose optimum the first fit started from; 0
  // when it started from the start (IdentSummary::coarse_subset_days).
  int subset_days = 0;
  // The time of the fits on a day subset, this rung's and a finer rung's
  // (IdentSummary::coarse_subset_runtime_s).
  double subset_runtime_s = 0.0;
  // The position in `fits` of the fit on all the days from the start that
  // followed a merge of the two nodes (MergedNodesWithBothCapacitancesFree);
  // 0 when there was none.
  std::size_t from_start_after_merge = 0;
  // The coarse stage's data (the first rung's averages), which the fine
  // stage's trial fits run on too.
  Drivers drivers;
  Measurements meas;
};

// The factor of the coarse stage's averaging, below 2 when there is none.
int CoarseFactor(const Drivers& drivers, const IdentOptions& options, const FreeSet& fs);

// IdentOptions::day_subset_stage: flags for the rows of every k-th solar
// day of d (k = max(2, days / 3): four or five days of 8 to 14, five of 29),
// and in *kept the number of days kept; empty for data covering fewer than
// kSubsetMinDays days.
constexpr double kSubsetMinDays = 8.0;

// The day subset's fit stops at this relative decrease (IdentOptions::ftol_rel),
// and the fit on all the days after it at this factor times the coarse one.
constexpr double kSubsetFtol = 1e-2;

constexpr double kAllDaysFtolFactor = 0.3;

std::vector<std::uint8_t> DaySubset(const Drivers& d, int* kept);

// The network with two capacitances (2N2Cwr) has two basins whose costs
// are close on a few days: C_PV at its lower bound, or the two nodes merged
// into one (U_coll at its upper bound) that holds the heat capacity in C_PV
// (C_coll small). A day subset's far descent lands in the second on some
// windows of the Table 6 protocol where the fit on all the days from the
// start finds the first (mean P_el MAE 0.188 -> 0.201 W/m² over its 29
// windows, core/fit/README.md). So when a fit with both capacitances free
// ends its fit on all the days from the subset's optimum with the nodes
// merged, a fit on all the days from the start follows, and the better of
// the two on the data as given is the fine stage's start (PickCoarse).
bool MergedNodesWithBothCapacitancesFree(const FreeSet& fs, const ParamVector& p);

// The coarse fits on the data averaged by `coarse_factor` (CoarseFactor, at
// least 2).
CoarseFits FitCoarse(const Drivers& drivers, const Measurements& meas, const IdentOptions& options,
                     const FreeSet& fs, int coarse_factor);

// The cost of p on the data as given where the fine stage will most likely
// start from p: with the Jacobian of all free parameters at p computed by
// the same run (Objective::DataCostWithJacobianAhead), when the fit asks
// for it first, at p itself: lad_lm (RunFit takes the start, not its round
// trip through the unit coordinates). NLopt's methods start at that round
// trip, a few ulps away, where the Jacobian would be in vain.
double CostOfTheFineStart(Objective& obj, const FreeSet& fs, const IdentOptions& options,
                          const ParamVector& p);

// The best of the coarse fits on the data as given, in their order: a
// misspecified model can have its coarse optimum far from the fine one, so
// one replaces *best only if it also beats the start (`initial_cost`). A
// single coarse fit that at least halved its cost (on the coarse data) took
// the fit far from a start that fitted badly: its optimum is then the fine
// stage's start (CostOfTheFineStart). From a start that fits well already
// (a warm start, the daemon's nightly case) the coarse optimum often loses
// to it on the data as given, and a Jacobian computed ahead there would be
// a run with sensitivities in vain: 15 % more instructions on the bench's
// warm starts at 1 min when every coarse optimum was priced ahead (callgrind,
// 18520fd against bf74886; core/fit/README.md).
void PickCoarse(const CoarseFits& coarse, Objective& obj, const FreeSet& fs,
                const IdentOptions& options, double initial_cost, ParamVector* best);

}  // namespace pvtwin::fit_internal
