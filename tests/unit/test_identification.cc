// Identification on data with a known answer (synthetic, seeds recorded) and
// on real data with provenance (tests/data/htwsaar-pvt).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "core/fit/identification.h"
#include "core/fit/iso9806.h"
#include "core/fit/lad_fit.h"
#include "core/model/sensitivities.h"
#include "core/synth/synthetic_plant.h"
#include "io/files/csv.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

struct Case {
  Series series;
  Drivers drivers;
  Measurements meas;
};

Case MakeCase(const Plant& plant, const std::string& variant, int days, double step_s,
              std::uint64_t seed, const SensorNoise& noise) {
  WeatherOptions weather;
  weather.num_days = days;
  weather.step_s = step_s;
  weather.seed = seed;
  weather.flow_mode = FlowMode::kVariable;  // varying flow separates r0 from r1
  Case c;
  c.series = MakeSyntheticPlantData(plant, weather, testing::SpecOf(variant),
                                    ReferenceTruthParams(plant), noise);
  std::string error;
  EXPECT_TRUE(PrepareDrivers(c.series, plant, testing::SpecOf(variant), &c.drivers, &error))
      << error;
  c.meas = MakeMeasurements(c.series, c.drivers);
  return c;
}

// The case's data prepared for a variant (other than the truth's: a
// misspecified fit).
struct Prepared {
  Drivers drivers;
  Measurements meas;
};
Prepared PrepareFor(const Case& c, const Plant& plant, const std::string& variant) {
  Prepared p;
  std::string error;
  EXPECT_TRUE(PrepareDrivers(c.series, plant, testing::SpecOf(variant), &p.drivers, &error))
      << error;
  p.meas = MakeMeasurements(c.series, p.drivers);
  return p;
}

// The same fit to the bit: parameters, cost, simulations charged (runs
// with sensitivities among them) and standard errors.
void ExpectTheSameFit(const IdentSummary& a, const IdentSummary& b) {
  EXPECT_EQ(a.params, b.params);
  EXPECT_EQ(a.final_cost_w_m2, b.final_cost_w_m2);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_EQ(a.sensitivity_runs, b.sensitivity_runs);
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  for (std::size_t i = 0; i < a.estimates.size(); ++i) {
    EXPECT_EQ(a.estimates[i].se_unit, b.estimates[i].se_unit) << i;
  }
}

// Noise-free data from the model itself: the identifiable parameters come
// back within 1 % and the MAE falls below 0.5 W/m².
TEST(IdentifySynthetic, NoiseFreeRecoversIdentifiableParameters) {
  const Plant plant = DesignExamplePlant();
  const ParamVector truth = ReferenceTruthParams(plant);
  for (const std::string variant : {"1N1Cwr", "2N1Ccolwr"}) {
    const Case c = MakeCase(plant, variant, 7, 120.0, /*seed=*/11, SensorNoise{});
    // Converge fully: the default tolerance stops where noise would dominate.
    IdentOptions options;
    options.optimizer.ftol_rel = 1e-10;
    options.optimizer.xtol_rel = 1e-10;
    options.prior_weight_w_m2 = 0.0;
    const IdentSummary s = Identify(c.drivers, c.meas, StartParams(plant), options);
    ASSERT_TRUE(s.ok) << s.BriefReport();
    EXPECT_LT(s.train.objective_w_m2(), 0.5) << s.BriefReport();
    int checked = 0;
    for (const ParamEstimate& e : s.estimates) {
      if (!e.free || e.undetermined || e.weak) continue;
      const double t = truth[static_cast<std::size_t>(e.param)];
      EXPECT_NEAR(e.value, t, 0.01 * std::fabs(t))
          << variant << " " << kParamTable[static_cast<std::size_t>(e.param)].name << " se "
          << e.se_unit << ": " << s.BriefReport();
      ++checked;
    }
    EXPECT_GE(checked, 8) << variant << ": too few parameters identified";
  }
}

// With realistic sensor noise the fit reaches the noise floor (the MAE of the
// true parameters on the same noisy data) within 10 %.
TEST(IdentifySynthetic, NoisyDataReachTheNoiseFloor) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 7, 60.0, /*seed=*/12, RealisticSensorNoise(13));
  SimOutputs truth_out;
  Simulate(c.drivers, ReferenceTruthParams(plant), &truth_out);
  const double floor = ComputeErrors(c.meas, truth_out, plant.area_m2).objective_w_m2();
  ASSERT_GT(floor, 0.1);  // the noise is there
  const IdentSummary s = Identify(c.drivers, c.meas, StartParams(plant), IdentOptions{});
  ASSERT_TRUE(s.ok) << s.BriefReport();
  EXPECT_LT(std::fabs(s.train.objective_w_m2() - floor), 0.1 * floor)
      << "fit " << s.train.objective_w_m2() << " W/m2, noise floor " << floor << " W/m2";
}

// The same fit with forward differences (d) and with the sensitivities (s);
// each must succeed, and only s may use runs with sensitivities.
struct BothFits {
  IdentSummary d, s;
};

BothFits FitWithBothDerivatives(const Case& c, const Plant& plant, IdentOptions options) {
  BothFits f;
  options.analytic_jacobian = false;
  f.d = Identify(c.drivers, c.meas, StartParams(plant), options);
  options.analytic_jacobian = true;
  f.s = Identify(c.drivers, c.meas, StartParams(plant), options);
  EXPECT_TRUE(f.d.ok && f.s.ok) << f.d.BriefReport() << "\n" << f.s.BriefReport();
  EXPECT_EQ(f.d.sensitivity_runs, 0);
  EXPECT_GT(f.s.sensitivity_runs, 0);
  return f;
}

// The LM fit with the Jacobian from the model run with sensitivities
// (IdentOptions::analytic_jacobian) reaches the fit of the forward
// differences on noisy data (within 0.5 % of the training MAE) and recovers
// the identifiable parameters of noise-free data within 1 %; a variant
// whose extension transforms the outputs (transport_delay's pipe) takes the
// derivatives through the transform.
TEST(IdentifySynthetic, SensitivityJacobianReachesTheSameFit) {
  const Plant plant = DesignExamplePlant();
  const Case noisy = MakeCase(plant, "2N1Ccolwr", 7, 60.0, /*seed=*/12, RealisticSensorNoise(13));
  const auto [d, s] = FitWithBothDerivatives(noisy, plant, IdentOptions{});
  EXPECT_NEAR(s.train.objective_w_m2(), d.train.objective_w_m2(), 0.005 * d.train.objective_w_m2());
  IdentOptions sensitivities;
  sensitivities.analytic_jacobian = true;

  const ParamVector truth = ReferenceTruthParams(plant);
  const Case clean = MakeCase(plant, "2N1Ccolwr", 7, 120.0, /*seed=*/11, SensorNoise{});
  sensitivities.optimizer.ftol_rel = 1e-10;
  sensitivities.optimizer.xtol_rel = 1e-10;
  sensitivities.prior_weight_w_m2 = 0.0;
  const IdentSummary c = Identify(clean.drivers, clean.meas, StartParams(plant), sensitivities);
  ASSERT_TRUE(c.ok) << c.BriefReport();
  EXPECT_LT(c.train.objective_w_m2(), 0.5) << c.BriefReport();
  int checked = 0;
  for (const ParamEstimate& e : c.estimates) {
    if (!e.free || e.undetermined || e.weak) continue;
    const double t = truth[static_cast<std::size_t>(e.param)];
    EXPECT_NEAR(e.value, t, 0.01 * std::fabs(t))
        << kParamTable[static_cast<std::size_t>(e.param)].name << ": " << c.BriefReport();
    ++checked;
  }
  EXPECT_GE(checked, 8) << c.BriefReport();

  const Case both = MakeCase(plant, "1N1Cwr+transport_delay", 3, 300.0, /*seed=*/15, SensorNoise{});
  const IdentSummary f = Identify(both.drivers, both.meas, StartParams(plant), sensitivities);
  EXPECT_TRUE(f.ok) << f.BriefReport();
  EXPECT_GT(f.sensitivity_runs, 0);
}

// Two threads (IdentOptions::threads) give the same fit to the bit: the runs
// with sensitivities split their columns, on data long enough for the split
// (7 days at 1 min, 11 columns: SimulateSensitivities splits from
// kSensitivitySplitWork rows × columns), and the start's cost runs beside
// the coarse stage; at 5 s (5 days, two residual rows per row) the normal
// equations and the standard errors' JᵀJ are summed as two halves too
// (from kSplitNormalEquationsRows rows).
TEST(IdentifySynthetic, TwoThreadsGiveTheSameFit) {
  const Plant plant = DesignExamplePlant();
  for (const auto& [days, step_s] : {std::pair{7, 60.0}, std::pair{5, 5.0}}) {
    SCOPED_TRACE(std::to_string(days) + " days at " + std::to_string(static_cast<int>(step_s)) +
                 " s");
    const Case c =
        MakeCase(plant, "2N1Ccolwr", days, step_s, /*seed=*/12, RealisticSensorNoise(13));
    ASSERT_GE(c.drivers.size() * 11, kSensitivitySplitWork);
    if (step_s < 60.0) {
      ASSERT_GE(static_cast<Eigen::Index>(2 * c.meas.rows.size()), kSplitNormalEquationsRows);
    }
    IdentOptions options;
    const IdentSummary one = Identify(c.drivers, c.meas, StartParams(plant), options);
    options.threads = 2;
    const IdentSummary two = Identify(c.drivers, c.meas, StartParams(plant), options);
    ASSERT_TRUE(one.ok && two.ok) << one.BriefReport() << "\n" << two.BriefReport();
    EXPECT_GT(two.sensitivity_runs, 0);
    ExpectTheSameFit(two, one);
  }
}

// lad_lm's start is priced by a run with sensitivities whose Jacobian the
// fit then takes first (IdentOptions::jacobian_ahead): the same fit to the
// bit as with a plain run before it (parameters, cost, counts, standard
// errors), from the coarse optimum and, without a coarse stage, from the
// start. The runs served without a model run show that the Jacobian and the
// start's cost were taken from that run: at the coarse rung's start and at
// the coarse optimum, or at the start. L-BFGS, which starts a few ulps away
// and so keeps the plain run, gives the same fit too, and each of its runs
// with sensitivities serves the cost at its point (Objective::CostGradient
// runs first). A Jacobian taken at another point or with other scales, or
// values that are not Simulate's, would move the fit. From a warm start the
// coarse optimum is priced by a plain run.
TEST(IdentifySynthetic, TheJacobianComputedAheadGivesTheSameFit) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 7, 120.0, /*seed=*/12, RealisticSensorNoise(13));
  IdentOptions no_coarse;
  no_coarse.coarse_step_s = 0.0;
  IdentOptions lbfgs;
  ASSERT_TRUE(SetIdentAlgorithm("lbfgs", &lbfgs));
  const std::pair<const char*, IdentOptions> cases[] = {
      {"lad_lm", IdentOptions{}}, {"lad_lm without a coarse stage", no_coarse}, {"lbfgs", lbfgs}};
  for (const auto& [name, options] : cases) {
    SCOPED_TRACE(name);
    IdentOptions plain = options;
    plain.jacobian_ahead = false;
    const IdentSummary ahead = Identify(c.drivers, c.meas, StartParams(plant), options);
    const IdentSummary before = Identify(c.drivers, c.meas, StartParams(plant), plain);
    ASSERT_TRUE(ahead.ok && before.ok) << ahead.BriefReport() << "\n" << before.BriefReport();
    ExpectTheSameFit(ahead, before);
    if (options.method == IdentMethod::kNlopt) {
      EXPECT_EQ(ahead.served_runs, before.served_runs);
      EXPECT_GE(before.served_runs, before.sensitivity_runs);
    } else {
      const int starts = options.coarse_step_s > 0.0 ? 2 : 1;
      EXPECT_EQ(ahead.served_runs - before.served_runs, starts * (kSensitivityRunCost + 1));
    }
  }
  // From a start that fits already (the fit's own result: a warm start) the
  // coarse fit hardly lowers its cost, and its optimum is priced by a plain
  // run, which it may lose to the start; only the coarse rung's start takes
  // its Jacobian ahead.
  const IdentSummary first = Identify(c.drivers, c.meas, StartParams(plant), IdentOptions{});
  ASSERT_TRUE(first.ok) << first.BriefReport();
  IdentOptions plain;
  plain.jacobian_ahead = false;
  const IdentSummary ahead = Identify(c.drivers, c.meas, first.params, IdentOptions{});
  const IdentSummary before = Identify(c.drivers, c.meas, first.params, plain);
  ASSERT_TRUE(ahead.ok && before.ok) << ahead.BriefReport() << "\n" << before.BriefReport();
  ExpectTheSameFit(ahead, before);
  EXPECT_EQ(ahead.served_runs - before.served_runs, kSensitivityRunCost + 1);
}

// The coarsest rung first fits on every k-th day (IdentOptions::
// day_subset_stage) and starts the fit on all the days from that optimum:
// on 10 days, four of them. The fit ends where the one without the stage
// ends, within the noise: the training cost within 0.2 % and every
// identified parameter within two standard errors. The subset's start and
// the coarse rung's start are priced ahead as well (one run with
// sensitivities serving the plain run and the Jacobian), and the fit is
// the same to the bit with plain runs before them. From a warm start the
// subset's fit does not halve its cost, so the fit on all the days starts
// from the start itself.
TEST(IdentifySynthetic, TheDaySubsetStageEndsWhereTheFitWithoutItEnds) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 10, 120.0, /*seed=*/21, RealisticSensorNoise(22));
  IdentOptions without;
  without.day_subset_stage = false;
  IdentOptions plain;
  plain.jacobian_ahead = false;
  const IdentSummary with = Identify(c.drivers, c.meas, StartParams(plant), IdentOptions{});
  const IdentSummary reference = Identify(c.drivers, c.meas, StartParams(plant), without);
  const IdentSummary before = Identify(c.drivers, c.meas, StartParams(plant), plain);
  ASSERT_TRUE(with.ok && reference.ok && before.ok) << with.BriefReport() << "\n"
                                                    << reference.BriefReport() << "\n"
                                                    << before.BriefReport();
  EXPECT_EQ(with.coarse_subset_days, 4);
  EXPECT_EQ(reference.coarse_subset_days, 0);
  // The subset's fit is a share of the coarse stage's time.
  EXPECT_GT(with.coarse_subset_runtime_s, 0.0);
  EXPECT_LT(with.coarse_subset_runtime_s, with.coarse_runtime_s);
  EXPECT_EQ(reference.coarse_subset_runtime_s, 0.0);
  EXPECT_NEAR(with.final_cost_w_m2, reference.final_cost_w_m2, 2e-3 * reference.final_cost_w_m2);
  ASSERT_EQ(with.estimates.size(), reference.estimates.size());
  for (std::size_t i = 0; i < with.estimates.size(); ++i) {
    const ParamEstimate& a = with.estimates[i];
    const ParamEstimate& b = reference.estimates[i];
    if (!a.free || a.undetermined || b.undetermined) continue;
    const double se = std::hypot(StdErrorInUnit(a), StdErrorInUnit(b));
    EXPECT_LE(std::fabs(a.value - b.value), 2.0 * se) << Info(a.param).name;
  }
  ExpectTheSameFit(with, before);
  EXPECT_EQ(with.served_runs - before.served_runs, 3 * (kSensitivityRunCost + 1));
  const IdentSummary warm = Identify(c.drivers, c.meas, with.params, IdentOptions{});
  ASSERT_TRUE(warm.ok) << warm.BriefReport();
  EXPECT_EQ(warm.coarse_subset_days, 0);
  // It ran, and its time is counted, though its optimum was not taken.
  EXPECT_GT(warm.coarse_subset_runtime_s, 0.0);
  EXPECT_LT(warm.coarse_subset_runtime_s, warm.coarse_runtime_s);
  EXPECT_LE(warm.final_cost_w_m2, with.final_cost_w_m2 * (1.0 + 1e-3));
}

// With both capacitances free (2N2Cwr) the network has two basins
// (core/fit/README.md): C_PV at its lower bound, or the two nodes merged
// into one (U_coll at its upper bound). The fit uses the day subset stage,
// and when the path from the subset's optimum ends with the nodes merged, a
// coarse fit on all the days from the start follows. On this 14-day window
// of the Table 6 protocol's data (`bench table6`, seed 1: the window before
// the test day 2024-07-12) the subset's path merges them; the fit must end
// where the fit without the stage ends, in the other basin. A fit that
// skipped the stage (coarse_subset_days 0) or kept the merged nodes fails.
TEST(IdentifySynthetic, TwoCapacitancesEndInTheBasinOfTheFitWithoutTheDaySubset) {
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = 14 + 29;
  weather.step_s = 60.0;
  weather.seed = 1;
  Case c;
  c.series = MakeSyntheticPlantData(plant, weather, testing::SpecOf("2N1Ccolwr"),
                                    ReferenceTruthParams(plant), RealisticSensorNoise(1))
                 .Between(1719528960, 1719528960 + 14 * 86400);
  const auto [d, meas] = PrepareFor(c, plant, "2N2Cwr");
  const IdentSummary with = Identify(d, meas, StartParams(plant), IdentOptions{});
  IdentOptions no_subset;
  no_subset.day_subset_stage = false;
  const IdentSummary without = Identify(d, meas, StartParams(plant), no_subset);
  ASSERT_TRUE(with.ok && without.ok) << with.BriefReport() << "\n" << without.BriefReport();
  EXPECT_EQ(with.coarse_subset_days, 4);
  EXPECT_EQ(without.coarse_subset_days, 0);
  // The window still puts the subset's path in the merged basin (if the
  // weather generator changes, this names why the test no longer tests it).
  const bool noted = std::ranges::any_of(with.notes, [](const std::string& n) {
    return n.find("merged the two nodes") != std::string::npos &&
           n.find("starts from that fit") != std::string::npos;
  });
  EXPECT_TRUE(noted) << with.BriefReport();
  for (const ParamEstimate& e : with.estimates) {
    if (e.param == Param::kUCollWM2K) {
      EXPECT_FALSE(e.at_bound) << with.BriefReport();
    }
  }
  EXPECT_NEAR(with.final_cost_w_m2, without.final_cost_w_m2, 2e-3 * without.final_cost_w_m2);
}

// The summary's cost and training errors are those of a fresh run at the
// result, to the bit, whether the fit's own last run served them (a repeat
// of the last run's parameters reuses its outputs) or a new run, with a
// fixed parameter (2Nwr) and without; a reuse that served another run's
// outputs fails here.
TEST(IdentifySynthetic, TheSummaryDescribesTheResult) {
  const Plant plant = DesignExamplePlant();
  for (const std::string variant : {"2N1Ccolwr", "2Nwr", "1N1Cwr"}) {
    const Case c = MakeCase(plant, "2N1Ccolwr", 7, 60.0, /*seed=*/12, RealisticSensorNoise(13));
    const auto [d, meas] = PrepareFor(c, plant, variant);
    const IdentSummary s = Identify(d, meas, StartParams(plant), IdentOptions{});
    ASSERT_TRUE(s.ok) << s.BriefReport();
    SimOutputs fresh;
    Simulate(d, s.params, &fresh);
    const ErrorMetrics e = ComputeErrors(meas, fresh, plant.area_m2);
    EXPECT_EQ(s.train.mae_p_el_w, e.mae_p_el_w) << variant;
    EXPECT_EQ(s.train.mae_q_th_w, e.mae_q_th_w) << variant;
    EXPECT_NEAR(s.final_cost_w_m2, e.objective_w_m2(), 1e-12 * e.objective_w_m2()) << variant;
  }
}

// A fit whose budget ends before its first step returns its start to the
// bit: the fit evaluates the start itself, not the start's round trip
// through the unit coordinates (which is the start only within rounding on
// a log scale), so that its first run is the one the caller's cost check
// has just made. A fit that took the round trip fails here.
TEST(IdentifySynthetic, AFitWithoutAStepReturnsItsStartToTheBit) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 3, 60.0, /*seed=*/12, RealisticSensorNoise(13));
  const auto [d, meas] = PrepareFor(c, plant, "2N1Ccolwr");
  IdentOptions options;
  options.optimizer.max_evaluations = 4;  // the start's cost and the first residuals: no step
  const ParamVector start = StartParams(plant);
  const IdentSummary s = Identify(d, meas, start, options);
  ASSERT_TRUE(s.ok) << s.BriefReport();
  for (std::size_t i = 0; i < kNumParams; ++i) {
    EXPECT_EQ(s.params[i], start[i]) << kParamTable[i].name;
  }
}

// Issue 16: an effect that changes the run's inputs keeps the exact
// columns of the parameters its hook does not read (the inverter limit with
// its electric effects here: the clipped power stays in the laminate as
// heat); only the hook's parameters (p_limit and A_PVT, which the limit
// scales) are differenced. The fit ends within 0.5 % of the training MAE of
// all-differences, on fewer simulations. A wrong column (the clipped rows'
// derivatives taken as if unclipped) would cost iterations or end the fit
// short.
TEST(IdentifySynthetic, EffectVariantsMixSensitivitiesAndDifferences) {
  const Plant plant = DesignExamplePlant();
  const Case c =
      MakeCase(plant, "2N1Ccolwr+pv_clipping", 7, 120.0, /*seed=*/12, RealisticSensorNoise(13));
  const auto [d, s] = FitWithBothDerivatives(c, plant, IdentOptions{});
  EXPECT_NEAR(s.train.objective_w_m2(), d.train.objective_w_m2(), 0.005 * d.train.objective_w_m2())
      << d.BriefReport() << "\n"
      << s.BriefReport();
  EXPECT_LT(s.evaluations, d.evaluations) << d.BriefReport() << "\n" << s.BriefReport();
  std::printf(
      "2N1Ccolwr+pv_clipping: %d simulations with differences, %d mixed (%d runs with "
      "sensitivities); training MAE %.4f, %.4f W/m2\n",
      d.evaluations, s.evaluations, s.sensitivity_runs, d.train.objective_w_m2(),
      s.train.objective_w_m2());
}

// NLopt's gradient methods take the gradient of the smoothed MAE from the
// run with sensitivities: L-BFGS reaches at least the fit it reaches with
// forward-difference gradients (at most 1 % above its training MAE) with
// fewer simulations. A wrong gradient would leave L-BFGS far off. (Below is
// allowed: the differenced gradient's error can stop L-BFGS early; here it
// ends 2 % above the exact gradient's fit.)
TEST(IdentifySynthetic, GradientMethodsUseTheSensitivities) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 7, 120.0, /*seed=*/12, RealisticSensorNoise(13));
  IdentOptions lbfgs;
  ASSERT_TRUE(SetIdentAlgorithm("lbfgs", &lbfgs));
  const auto [d, s] = FitWithBothDerivatives(c, plant, lbfgs);
  EXPECT_LE(s.train.objective_w_m2(), 1.01 * d.train.objective_w_m2()) << d.BriefReport() << "\n"
                                                                       << s.BriefReport();
  EXPECT_LT(s.evaluations, d.evaluations) << d.BriefReport() << "\n" << s.BriefReport();
}

// A_PVT multiplies every flux: freed together with the others it spans a flat
// direction, which must be reported and resolved by fixing a parameter at its
// reference value instead of returning an arbitrary point on the ridge.
TEST(IdentifySynthetic, FlatDirectionIsReportedAndFixed) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "1N1C", 5, 300.0, /*seed=*/14, SensorNoise{});
  IdentOptions options;
  options.free = DefaultFreeParams(testing::SpecOf("1N1C"));
  options.free.set(static_cast<std::size_t>(Param::kAreaM2));
  const IdentSummary s = Identify(c.drivers, c.meas, StartParams(plant), options);
  ASSERT_TRUE(s.ok) << s.BriefReport();
  EXPECT_LT(s.train.objective_w_m2(), 0.5);
  int undetermined = 0;
  for (const ParamEstimate& e : s.estimates) {
    if (!e.undetermined) continue;
    ++undetermined;
    EXPECT_EQ(e.value, e.start) << "an undetermined parameter stays at its reference value";
  }
  EXPECT_GE(undetermined, 1);
  std::string all_notes;
  for (const std::string& n : s.notes) all_notes += n + "\n";
  EXPECT_NE(all_notes.find("not determined"), std::string::npos) << all_notes;
}

// Issue 16: the trial fit that decides whether a weakly determined
// parameter is fixed runs on the coarse stage's data, and its optimum is
// priced on the data as given. Its verdict must hold on those data: a
// parameter it kept free (fixing it would raise the MAE by more than
// fix_cost_tolerance) costs more than that when a whole fit on the data as
// given holds it at its reference value. A trial that stopped far from its
// optimum, or priced another point, keeps free what a fit could fix cheaply.
// Which parameters a fit keeps free depends on its path, so the test takes
// three misspecified variants that keep some (1Nwr and 2Nwr the fluid
// resistance, 2N1CcolwrI the back loss, on these data) and asks for one at
// least over all of them. 1N keeps u_front_w_m2k and u_back_w_m2k, the
// second without a trial of its own, as the mirror image of the first.
TEST(IdentifySynthetic, AParameterItsTrialKeptFreeCostsMoreWhenFixed) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 4, 60.0, /*seed=*/12, RealisticSensorNoise(13));
  int kept = 0;
  for (const std::string variant : {"1N", "1Nwr", "2Nwr", "2N1CcolwrI"}) {
    const auto [d, meas] = PrepareFor(c, plant, variant);
    const IdentOptions options;
    const IdentSummary s = Identify(d, meas, StartParams(plant), options);
    ASSERT_TRUE(s.ok) << s.BriefReport();
    for (const ParamEstimate& e : s.estimates) {
      if (!e.weak) continue;
      IdentOptions held = options;
      held.free = DefaultFreeParams(d.spec);
      held.free.reset(static_cast<std::size_t>(e.param));
      held.fix_unidentifiable = false;
      const IdentSummary f = Identify(d, meas, StartParams(plant), held);
      ASSERT_TRUE(f.ok) << f.BriefReport();
      ++kept;
      std::printf("%s: %s kept free, %.4f W/m2; held at %.4g: %.4f W/m2\n", variant.c_str(),
                  Info(e.param).name.data(), s.final_cost_w_m2, e.start, f.final_cost_w_m2);
      EXPECT_GT(f.final_cost_w_m2, s.final_cost_w_m2 * (1.0 + options.fix_cost_tolerance))
          << variant << " " << Info(e.param).name;
    }
  }
  EXPECT_GE(kept, 1) << "no variant kept a weakly determined parameter free";
}

// The time split that `calibrate --timing` and `bench table6` print: the
// identifiability analysis (standard errors, the rounds that decide which
// undetermined parameters to fix) is a part of the fine stage, with its
// runs (the trial fits' on the coarse data among them) and the trial fits'
// time as a part of its own, and runs nothing when the fit fixes nothing by
// itself. 1Nwr on these data has weakly determined parameters, so its
// rounds run the model, a trial fit among them.
TEST(IdentifySynthetic, TheFixingRoundsAreAPartOfTheFineStageWithTheirRuns) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 4, 60.0, /*seed=*/12, RealisticSensorNoise(13));
  const auto [d, meas] = PrepareFor(c, plant, "1Nwr");
  IdentOptions options;
  const IdentSummary s = Identify(d, meas, StartParams(plant), options);
  ASSERT_TRUE(s.ok) << s.BriefReport();
  ASSERT_FALSE(s.notes.empty()) << "1Nwr on these data is expected to have fixing rounds";
  EXPECT_GT(s.fixing_runtime_s, 0.0);
  EXPECT_LE(s.fixing_runtime_s, s.runtime_s - s.coarse_runtime_s);
  EXPECT_GT(s.fixing_evaluations, 0);
  EXPECT_LE(s.fixing_coarse_evaluations, s.fixing_evaluations);
  EXPECT_LE(s.fixing_evaluations, s.evaluations - s.coarse_evaluations);
  // The trial fits run on the coarse data: their time is there when their
  // runs are, and a share of the rounds' time.
  EXPECT_EQ(s.trial_runtime_s > 0.0, s.fixing_coarse_evaluations > 0);
  EXPECT_LT(s.trial_runtime_s, s.fixing_runtime_s);

  options.fix_unidentifiable = false;
  const IdentSummary f = Identify(d, meas, StartParams(plant), options);
  ASSERT_TRUE(f.ok) << f.BriefReport();
  EXPECT_EQ(f.fixing_evaluations, 0);
  EXPECT_EQ(f.fixing_coarse_evaluations, 0);
  EXPECT_EQ(f.trial_runtime_s, 0.0);
}

// After a coarse stage the fit on the data as given polishes its optimum
// and ends before a step predicted to gain less than ftol_rel·O
// (IdentOptions::polish_stop_prediction_factor 1), where a fit from the
// start asks 0.3 of it. On these data 2N1Cpvwr (misspecified: the truth is
// 2N1Ccolwr) walks a valley at 1 min: the polish takes fewer runs and ends
// within 0.5 % of the cost of the fit that asks for the margin. Without a
// coarse stage the fit starts at the start, and the factor does not apply:
// the fit is the same to the bit.
TEST(IdentifySynthetic, ThePolishAfterTheCoarseStageStopsBeforeAStepBelowFtol) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 10, 60.0, /*seed=*/21, RealisticSensorNoise(22));
  const auto [d, meas] = PrepareFor(c, plant, "2N1Cpvwr");
  IdentOptions margin;
  margin.polish_stop_prediction_factor = LadFitOptions{}.stop_prediction_factor;
  const IdentSummary polish = Identify(d, meas, StartParams(plant), IdentOptions{});
  const IdentSummary tight = Identify(d, meas, StartParams(plant), margin);
  ASSERT_TRUE(polish.ok && tight.ok) << polish.BriefReport() << "\n" << tight.BriefReport();
  ASSERT_GT(polish.coarse_evaluations, 0);
  // The fine stage's own fit: its runs without the coarse stage's and the
  // fixing rounds'.
  auto own = [](const IdentSummary& s) {
    return s.evaluations - s.coarse_evaluations - s.fixing_evaluations;
  };
  EXPECT_EQ(polish.coarse_evaluations, tight.coarse_evaluations);
  EXPECT_LT(own(polish), own(tight)) << polish.BriefReport() << "\n" << tight.BriefReport();
  EXPECT_LE(polish.final_cost_w_m2, tight.final_cost_w_m2 * (1.0 + 5e-3));

  IdentOptions no_coarse;
  no_coarse.coarse_step_s = 0.0;
  margin.coarse_step_s = 0.0;
  const IdentSummary from_start = Identify(d, meas, StartParams(plant), no_coarse);
  const IdentSummary from_start_margin = Identify(d, meas, StartParams(plant), margin);
  ASSERT_TRUE(from_start.ok) << from_start.BriefReport();
  EXPECT_EQ(from_start.coarse_evaluations, 0);
  ExpectTheSameFit(from_start, from_start_margin);
}

// 1N sees u_front_w_m2k and u_back_w_m2k only as their sum: with the same
// range, reference value and value, fixing either is the same fit with the
// two exchanged. When a trial fit kept the first free, the second gets the
// same verdict at the same cost without a trial of its own: the fixing
// rounds run at most one trial's runs on the coarse data, where two trials
// took twice that.
TEST(IdentifySynthetic, TheMirrorOfAParameterKeptFreeIsKeptWithoutASecondTrial) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 4, 60.0, /*seed=*/12, RealisticSensorNoise(13));
  const auto [d, meas] = PrepareFor(c, plant, "1N");
  const IdentOptions options;
  const IdentSummary s = Identify(d, meas, StartParams(plant), options);
  ASSERT_TRUE(s.ok) << s.BriefReport();
  std::vector<std::string> kept;
  for (const std::string& note : s.notes) {
    std::printf("%s\n", note.c_str());
    if (note.find("kept free") != std::string::npos) kept.push_back(note);
  }
  ASSERT_EQ(kept.size(), 2u) << "u_front_w_m2k and u_back_w_m2k both kept free on these data";
  const auto cost_in = [](const std::string& note) { return note.substr(note.rfind("by ")); };
  EXPECT_EQ(cost_in(kept[0]), cost_in(kept[1]));
  const int free_count = static_cast<int>(DefaultFreeParams(d.spec).count());
  const int one_trial = 8 * (free_count + 2) + 2;  // its budget, and two runs to spare
  std::printf("runs on the coarse data in the fixing rounds: %d (one trial at most %d)\n",
              s.fixing_coarse_evaluations, one_trial);
  EXPECT_GT(s.fixing_coarse_evaluations, 0);
  EXPECT_LE(s.fixing_coarse_evaluations, one_trial);
}

TEST(IdentifyFailures, TooLittleDataIsAFailureWithReason) {
  const Plant plant = DesignExamplePlant();
  Case c = MakeCase(plant, "1N1C", 1, 600.0, 15, SensorNoise{});
  c.meas.rows.resize(5);
  const IdentSummary s = Identify(c.drivers, c.meas, StartParams(plant), IdentOptions{});
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.failure_reason.find("too little data"), std::string::npos) << s.failure_reason;
}

// A start at which the model gives no finite output fails with that reason,
// on one thread and on two, where the start's cost runs beside the coarse
// stage instead of before it.
TEST(IdentifyFailures, ANonFiniteStartIsAFailureOnEitherThreadCount) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 2, 60.0, 15, SensorNoise{});
  ParamVector start = StartParams(plant);
  start[static_cast<std::size_t>(Param::kUBackWM2K)] = std::nan("");
  for (int threads : {1, 2}) {
    IdentOptions options;
    options.threads = threads;
    const IdentSummary s = Identify(c.drivers, c.meas, start, options);
    EXPECT_FALSE(s.ok) << threads;
    EXPECT_NE(s.failure_reason.find("non-finite outputs at the start values"), std::string::npos)
        << threads << ": " << s.failure_reason;
  }
}

TEST(IdentifyFailures, EvaluationCapNeverReturnsAWorseFit) {
  const Plant plant = DesignExamplePlant();
  const Case c = MakeCase(plant, "2N1Ccolwr", 2, 600.0, 16, RealisticSensorNoise(17));
  for (const char* algorithm : {"lad_lm", "sbplx", "bobyqa"}) {
    IdentOptions options;
    ASSERT_TRUE(SetIdentAlgorithm(algorithm, &options));
    options.optimizer.max_evaluations = 15;
    const IdentSummary s = Identify(c.drivers, c.meas, StartParams(plant), options);
    EXPECT_LE(s.final_cost_w_m2, s.initial_cost_w_m2) << s.BriefReport();
    EXPECT_LE(s.evaluations, 15 + 2) << s.BriefReport();  // + the start and the final check
    if (s.ok) {
      EXPECT_TRUE(std::isfinite(s.final_cost_w_m2));
    }
  }
}

// A warm start, as the daemon's nightly calibration from the last one: a
// variant misspecified for the 2N1Ccolwr truth fitted on days 0-4, then
// from that fit on days 1-5. Fixing the parameters these data do not
// determine may cost up to fix_cost_tolerance, and from a start that good
// the result can end above the start (the identification used to fail
// there). The start keeps the fixed parameters at their start values too:
// it is the result, with a note. Whether a window ends above its start
// depends on the fit's path; these three did at some version of the fit
// (1Nwr seed 2 before the secant iteration between Jacobians, 1N seed 4
// and 2Nwr seed 9 with it; a search of 5 variants × 12 seeds found no
// other), and one of them at least must reach the branch.
TEST(IdentifyWarmStart, AStartThatFitsBetterThanTheResultIsKept) {
  const Plant plant = DesignExamplePlant();
  int reached = 0;
  for (const auto& [variant_name, seed] :
       std::vector<std::pair<std::string, unsigned>>{{"1Nwr", 2}, {"1N", 4}, {"2Nwr", 9}}) {
    const std::string variant = variant_name;  // a lambda below captures it (clang 14)
    WeatherOptions weather;
    weather.num_days = 6;
    weather.step_s = 300.0;
    weather.seed = seed;
    const Series all = MakeSyntheticPlantData(plant, weather, testing::SpecOf("2N1Ccolwr"),
                                              ReferenceTruthParams(plant), RealisticSensorNoise(2));
    constexpr std::size_t kDay = 288;
    auto fit = [&](std::size_t first_row, const ParamVector& start) {
      const Series s = all.Slice(first_row, first_row + 5 * kDay);
      Drivers d;
      std::string error;
      EXPECT_TRUE(PrepareDrivers(s, plant, testing::SpecOf(variant), &d, &error)) << error;
      return Identify(d, MakeMeasurements(s, d), start, IdentOptions{});
    };
    const IdentSummary first = fit(0, StartParams(plant));
    ASSERT_TRUE(first.ok) << variant << " " << first.BriefReport();
    const IdentSummary warm = fit(kDay, first.params);
    ASSERT_TRUE(warm.ok) << variant << " " << warm.failure_reason;
    EXPECT_LE(warm.final_cost_w_m2, warm.initial_cost_w_m2) << variant;
    std::string notes;
    for (const std::string& n : warm.notes) notes += n + "\n";
    if (notes.find("the start values fit better than the fit's result") == std::string::npos) {
      continue;
    }
    ++reached;
    std::printf("%s, seed %u: the start kept, %.4f W/m2\n", variant.c_str(), seed,
                warm.final_cost_w_m2);
    EXPECT_EQ(warm.final_cost_w_m2, warm.initial_cost_w_m2) << variant;
    EXPECT_EQ(warm.params, first.params) << variant;
    EXPECT_NEAR(warm.train.objective_w_m2(), warm.final_cost_w_m2, 1e-9 * warm.final_cost_w_m2)
        << variant;
  }
  EXPECT_GE(reached, 1) << "no window ended above its start: the branch was not reached";
}

TEST(IdentOptions, IsValidNamesFieldValueAndRule) {
  IdentOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.prior_weight_w_m2 = -1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "prior_weight_w_m2 = -1: must be >= 0");
  o = IdentOptions{};
  o.optimizer.max_evaluations = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("max_evaluations = 0"), std::string::npos) << why;
  o = IdentOptions{};
  o.threads = 3;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "threads = 3: must be 1 or 2");
  EXPECT_TRUE(SetIdentAlgorithm("sbplx", &o));
  EXPECT_EQ(IdentAlgorithmName(o), "sbplx");
  EXPECT_TRUE(SetIdentAlgorithm("lad_lm", &o));
  EXPECT_EQ(IdentAlgorithmName(o), "lad_lm");
  EXPECT_FALSE(SetIdentAlgorithm("gradient_descent", &o));
}

constexpr double kBenchWindMS = 3.5;     // PROVENANCE.md: blower, ≈ 3.5 m/s
constexpr double kBenchFlowKgS = 0.033;  // the test days' flow

// Real data (htw saar, PROVENANCE.md): identify on the day with the fluid
// ~8 K above ambient, predict the day near ambient. Thresholds are about
// 1.5 × what this model reaches (doc/validation.md), so a regression in
// the physics or the fit fails here.
TEST(IdentifyRealData, HtwSaarDay3PredictsDay1) {
  const std::string dir = std::string(PVTWIN_DATA_DIR) + "/htwsaar-pvt/";
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig(dir + "plant.toml", &config, &errors));
  // The fit with the measured long-wave channel as the paper uses it (the
  // default would replace it by an estimate: it is implausible, see
  // SensorFaults.OnlyTheLongWaveChannelOnTheHtwSaarDays).
  config.plant.sky = SkySource::kMeasured;
  Series train, test;
  CsvReadOptions csv;
  csv.fluid_density_kg_m3 = config.plant.fluid_density_kg_m3;
  ASSERT_TRUE(ReadCanonicalCsv(dir + "day3_clear_medium_dT.csv", csv, &train, &errors, nullptr));
  ASSERT_TRUE(ReadCanonicalCsv(dir + "day1_clear_low_dT.csv", csv, &test, &errors, nullptr));
  const ModelSpec spec = testing::SpecOf("2N1CcolwrI");
  Drivers dtrain, dtest;
  std::string error;
  ASSERT_TRUE(PrepareDrivers(train, config.plant, spec, &dtrain, &error)) << error;
  ASSERT_TRUE(PrepareDrivers(test, config.plant, spec, &dtest, &error)) << error;
  const IdentSummary s =
      Identify(dtrain, MakeMeasurements(train, dtrain), StartParams(config.plant), IdentOptions{});
  ASSERT_TRUE(s.ok) << s.BriefReport();
  EXPECT_LT(s.train.nmae_p_el, 0.015);
  EXPECT_LT(s.train.nmae_q_th, 0.06);
  SimOutputs sim;
  Simulate(dtest, s.params, &sim);
  const ErrorMetrics held_out =
      ComputeErrors(MakeMeasurements(test, dtest), sim, config.plant.area_m2);
  EXPECT_LT(held_out.nmae_p_el, 0.02);
  EXPECT_LT(held_out.nmae_q_th, 0.18);

  // Bounds. Parameters that run to a bound are reported as such
  // (IdentSummary::estimates[].at_bound, which `pvtwin calibrate` prints as
  // "at upper bound": test_cli_model.cc checks the printout). Three may run
  // to their upper bound on this day and one to its lower bound, depending
  // on the path of the fit; any other parameter at a bound fails here. (The
  // fit ends on a path where the identifiability analysis fixes
  // u_front_w_m2k, f_th, n_wind and eps_pvt as not determined by the data,
  // with the exact Jacobian and with forward differences; forward
  // differences used to leave u_front_w_m2k and f_th at their upper
  // bounds.)
  //  * u_front_w_m2k → 1e3: in the paper's wind form (2.8) 1/U_front,w =
  //    1/U_front + r_refwind·v^n, U_front → ∞ leaves the front resistance to
  //    the wind term alone. With the blower's near-constant 3.5 m/s the
  //    still-air part cannot be told from the wind part; the paper's own
  //    fits wander the same way (Fig. 8, U_front 2.6e2 … 1e5).
  //  * f_th → 1.2: F_th > 1 absorbs more than the incident irradiance, which
  //    is not physical. It pairs with u_back ≈ 25 W/(m²K) on a rear-insulated
  //    collector: one day at T_m − T_amb ≈ 8 K does not separate gain from
  //    loss, and the fit trades more of both (see the ISO 9806 equivalents).
  //  * n_wind → 1.2: at a near-constant wind speed v^n is one constant
  //    factor that r_refwind takes up as well; only the minutes of another
  //    speed set n.
  //  * r0_fluid_m2k_w → 1e-4: the flow of day 3 stays within 0.0322–0.0332
  //    kg/s, so the fluid-side resistance r0 + r1/(2w) of eq. (2.7) is one
  //    constant sum that r1_fluid can hold alone. The fit puts r0 near
  //    zero on every path, with a standard error (≈ 1e-3 m²K/W) several
  //    times its distance from the bound; whether it ends at 1e-4 or at
  //    2e-4 depends on the path.
  const std::set<Param> may_be_at_upper_bound = {Param::kUFrontWM2K, Param::kFTh, Param::kNWind};
  const std::set<Param> may_be_at_lower_bound = {Param::kR0FluidM2KW};
  for (const ParamEstimate& e : s.estimates) {
    if (!e.free || e.undetermined) continue;
    const std::string name(Info(e.param).name);
    if (may_be_at_upper_bound.count(e.param) > 0 && e.at_bound) {
      EXPECT_NEAR(e.value, e.upper, 1e-3 * (e.upper - e.lower)) << name;
    } else if (may_be_at_lower_bound.count(e.param) > 0 && e.at_bound) {
      EXPECT_GT(StdErrorInUnit(e), 2.0 * e.value) << name << ": the data hold it off its bound";
    } else {
      EXPECT_FALSE(e.at_bound) << name << " = " << e.value << " at a bound of [" << e.lower << ", "
                               << e.upper << "]";
    }
  }

  // Datasheet (PROVENANCE.md, values quoted by IDEAS for "PVT A").
  auto fitted = [&s](Param p) { return s.params[static_cast<std::size_t>(p)]; };
  // η_PV,ref against the nameplate η_el = 0.1687. 5 %: the module's power
  // tolerance (a few %) plus the bench's MPP tracking and wiring. Fit: 0.1657.
  EXPECT_NEAR(fitted(Param::kEtaPvRef), 0.1687, 0.05 * 0.1687);
  // Thermal side through its ISO 9806 equivalents at the bench's wind:
  //   η0(u) = η0·(1 − c6·u) = 0.475·(1 − 0.003·3.5) = 0.4700
  //   c1 + c3·u = 7.411 + 1.7·3.5 = 13.36 W/(m²K)
  // The fit gives η0 = 0.429 (−8.7 %) and 16.6 W/(m²K) (+25 %). The low η0
  // is in the data, not the fit: the measured heat of day 1, at T_m ≈ T_amb,
  // is 0.42·G on average (G > 300 W/m², valid rows, IAM losses of the
  // day's angles included), where the datasheet would give ≈ 0.47. The loss coefficient is set by
  // one day at a reduced temperature (T_m − T_amb)/G ≈ 0.011 m²K/W (ISO 9806 tests span ≈ 0 …
  // 0.08), so it is only loosely determined, and it trades off against F_th
  // (above). Bounds: η0 within 10 %, the loss within 50 %.
  const Iso9806Equivalents iso =
      Iso9806EquivalentsOf(config.plant, spec, s.params, kBenchFlowKgS, kBenchWindMS);
  ASSERT_TRUE(iso.ok);
  EXPECT_NEAR(iso.eta0, 0.4700, 0.10 * 0.4700);
  EXPECT_NEAR(iso.loss_w_m2k, 13.36, 0.50 * 13.36);
  // Heat capacity: the datasheet's C = 42 200 J/(m²K) is the whole
  // collector's; 2N1Ccol puts one capacitance on the collector node and
  // none on the PV laminate, and identifies 15 400 J/(m²K) (0.37 × C) here.
  // This is a known disagreement, not asserted as agreement: it is recorded
  // so that a change shows up in the test's XML output.
  ::testing::Test::RecordProperty("c_coll_over_datasheet_c",
                                  std::to_string(fitted(Param::kCCollJM2K) / 42200.0));
}

}  // namespace
}  // namespace pvtwin
