// Identification of every effect on synthetic data with a known answer:
// truth = base + effect at its typical magnitude (EffectModule::typical_truth),
// realistic noise and the paper's data defects (seeds recorded); fitting
// base + effect recovers the effect's parameter and reaches the held-out
// noise floor, while the base model alone leaves a gap.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/data/qc.h"
#include "core/effects/effects.h"
#include "core/fit/identification.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/effect_named.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

constexpr int kIdentDays = 10;
constexpr int kTrainDays = 7;

// Tolerances: a few standard errors of each parameter on 7 training days
// with realistic noise; U_coll is only weakly determined by P_el and Q_u
// (the PV-to-absorber temperature difference shows only through η_PV's
// temperature coefficient), hence its wide tolerance.
struct IdentCase {
  const char* effect;  // vocabulary name
  const char* base;    // the model without the effect
  Param checked;       // parameter whose truth must come back
  double tolerance;    // absolute, in the parameter's unit
  std::uint64_t seed;
  // Start value of `checked` for the fit; NaN: the reference start value
  // (params.h). Either way the start must be more than `tolerance` from the
  // truth, or recovering the truth would prove nothing.
  double start = std::numeric_limits<double>::quiet_NaN();
  // Fit to ftol = xtol = 1e-9 instead of the defaults, for a parameter that
  // moves the objective by less than the default ftol_rel (1e-3).
  bool converge_fully = false;
  // The base model must leave a held-out gap of more than kGapSe standard
  // errors of the noise floor; false where the measured gap is within the
  // noise at the effect's typical magnitude (said at the case).
  bool gap_visible = true;
};

// A gap "well above the noise": the noise alone moves a held-out MAE by
// about one standard error (sd of the rows' absolute errors / √rows, ≈ 0.025
// W/m² here, 2 % of the floor); four of them is far outside that.
constexpr double kGapSe = 4.0;

struct Fit {
  IdentSummary summary;
  double heldout_w_m2 = 0.0;
  // Standard error of heldout_w_m2 from the row-to-row scatter of the
  // held-out absolute errors (|e_P_el| + |e_Q_u|)/A: sd/√rows.
  double heldout_se_w_m2 = 0.0;
};

// Fits `variant` on the first kTrainDays and scores it on the rest.
Fit FitAndScore(const Series& data, const Plant& plant, const ModelSpec& spec,
                const ParamVector* fixed_params = nullptr, const ParamVector* start = nullptr,
                bool converge_fully = false) {
  const std::int64_t split_s = data.time_s[0] + kTrainDays * 86400;
  std::size_t split = 0;
  while (split < data.size() && data.time_s[split] < split_s) ++split;
  const Series train = data.Slice(0, split);
  Drivers train_d, all_d;
  std::string error;
  EXPECT_TRUE(PrepareDrivers(train, plant, spec, &train_d, &error)) << error;
  EXPECT_TRUE(PrepareDrivers(data, plant, spec, &all_d, &error)) << error;
  Fit fit;
  ParamVector params;
  if (fixed_params != nullptr) {
    params = *fixed_params;
  } else {
    IdentOptions options;
    if (converge_fully) {
      options.optimizer.ftol_rel = 1e-9;
      options.optimizer.xtol_rel = 1e-9;
    }
    fit.summary = Identify(train_d, MakeMeasurements(train, train_d),
                           start != nullptr ? *start : StartParams(plant), options);
    EXPECT_TRUE(fit.summary.ok) << fit.summary.BriefReport();
    params = fit.summary.params;
  }
  Measurements held = MakeMeasurements(data, all_d);
  std::vector<std::uint32_t> rows;
  for (std::uint32_t r : held.rows) {
    if (r >= split) rows.push_back(r);
  }
  held.rows = rows;
  SimOutputs out;
  Simulate(all_d, params, &out);
  fit.heldout_w_m2 = ComputeErrors(held, out, plant.area_m2).objective_w_m2();
  double sum = 0.0, sum_sq = 0.0;
  for (std::uint32_t r : held.rows) {
    const double e =
        (std::fabs(out.p_el_w[r] - held.p_el_w[r]) + std::fabs(out.q_th_w[r] - held.q_th_w[r])) /
        plant.area_m2;
    sum += e;
    sum_sq += e * e;
  }
  const double n = static_cast<double>(held.rows.size());
  const double var = (sum_sq - sum * sum / n) / (n - 1.0);
  fit.heldout_se_w_m2 = std::sqrt(var / n);
  return fit;
}

class EffectIdentification : public ::testing::TestWithParam<IdentCase> {};

TEST_P(EffectIdentification, RecoversTheEffectAndReachesTheNoiseFloor) {
  const IdentCase c = GetParam();
  const Plant plant = DesignExamplePlant();
  const ModelSpec base = testing::SpecOf(c.base);
  const ModelSpec with = WithEffect(base, testing::EffectNamed(c.effect));
  SyntheticOptions options;
  std::string error;
  ASSERT_TRUE(DefaultSyntheticOptions(plant, with.Name(), kIdentDays, c.seed, &options, &error))
      << error;
  Series data = MakeSyntheticPlantData(plant, options);
  ApplyPaperCorrections(&data);

  ParamVector start = StartParams(plant);
  const std::size_t checked = static_cast<std::size_t>(c.checked);
  if (!std::isnan(c.start)) start[checked] = c.start;
  ASSERT_GT(std::fabs(start[checked] - options.truth[checked]), c.tolerance)
      << "the fit would pass by staying at its start value";

  const auto t0 = std::chrono::steady_clock::now();
  const Fit truth = FitAndScore(data, plant, with, &options.truth);
  const Fit fit_with = FitAndScore(data, plant, with, nullptr, &start, c.converge_fully);
  const Fit fit_base = FitAndScore(data, plant, base, nullptr, nullptr, c.converge_fully);
  const double runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double value = fit_with.summary.params[static_cast<std::size_t>(c.checked)];
  const double truth_value = options.truth[static_cast<std::size_t>(c.checked)];
  std::printf(
      "%-16s truth %-28s held-out MAE: truth %.3f (se %.4f), with %.3f, base %.3f W/m2; %s = "
      "%.4g (truth %.4g, start %.4g); %.1f s\n",
      c.effect, with.Name().c_str(), truth.heldout_w_m2, truth.heldout_se_w_m2,
      fit_with.heldout_w_m2, fit_base.heldout_w_m2, std::string(Info(c.checked).name).c_str(),
      value, truth_value, start[checked], runtime_s);
  EXPECT_NEAR(value, truth_value, c.tolerance) << fit_with.summary.BriefReport();
  if (std::string_view(c.effect) == "shading") {
    // Identifiable is what the sun path crosses: the obstacle's edge
    // elevation and the window's west edge (June afternoons). The east edge
    // is not determined by summer data (the morning sun passes it above the
    // obstacle), so the centre and width are not checked separately.
    auto at = [](const ParamVector& p, Param name) { return p[static_cast<std::size_t>(name)]; };
    const ParamVector& fit = fit_with.summary.params;
    const ParamVector& truth_p = options.truth;
    EXPECT_NEAR(at(fit, Param::kShadeElevationRad), at(truth_p, Param::kShadeElevationRad), 0.02);
    EXPECT_NEAR(at(fit, Param::kShadeAzimuthRad) + 0.5 * at(fit, Param::kShadeWidthRad),
                at(truth_p, Param::kShadeAzimuthRad) + 0.5 * at(truth_p, Param::kShadeWidthRad),
                0.03);
  }
  if (std::string_view(c.effect) == "transport_delay") {
    const std::size_t pipe = static_cast<std::size_t>(Param::kUPipeWM2K);
    EXPECT_NEAR(fit_with.summary.params[pipe], options.truth[pipe], 0.3);
  }
  if (std::string_view(c.effect) == "irradiance_bias") {
    // Without the second source the fit absorbs the pyranometer's 6 % low
    // reading into η_PV; with it, η_PV comes back unbiased.
    const std::size_t eta = static_cast<std::size_t>(Param::kEtaPvRef);
    EXPECT_GT(fit_base.summary.params[eta] - truth_value, 0.5 * 0.06 * truth_value);
  } else if (c.gap_visible) {
    EXPECT_GT(fit_base.heldout_w_m2, truth.heldout_w_m2 + kGapSe * truth.heldout_se_w_m2)
        << "the base model's held-out MAE is within " << kGapSe
        << " noise standard errors of the floor";
  }
  EXPECT_LT(fit_with.heldout_w_m2, 1.1 * truth.heldout_w_m2 + 0.1);
}

// The obstacle's geometry from the reference start (a shade due south that
// the fit can only move where the sun already crosses it) on twelve data
// seeds: identification restarts the coarse stage from the residuals of the
// model without the obstacle (the module's start_from_residuals). It finds
// the obstacle on 11 of them (the twelfth, 111, ends with none at a training
// MAE as low as the others'); without that restart it was found on 7, and
// on 4 once the coarse stage stopped averaging across pump starts and stops.
TEST(EffectIdentificationShading, FindsTheObstacleFromTheReferenceStart) {
  const Plant plant = DesignExamplePlant();
  const ModelSpec spec = WithEffect(testing::SpecOf("1N1Cwr"), testing::EffectNamed("shading"));
  int found = 0;
  std::string misses;
  for (std::uint64_t seed = 101; seed <= 112; ++seed) {
    SyntheticOptions options;
    std::string error;
    ASSERT_TRUE(DefaultSyntheticOptions(plant, spec.Name(), kIdentDays, seed, &options, &error))
        << error;
    Series data = MakeSyntheticPlantData(plant, options);
    ApplyPaperCorrections(&data);
    const Fit fit = FitAndScore(data, plant, spec);
    auto at = [](const ParamVector& p, Param name) { return p[static_cast<std::size_t>(name)]; };
    const ParamVector& f = fit.summary.params;
    const ParamVector& t = options.truth;
    const bool ok =
        std::fabs(at(f, Param::kShadeMismatch) - at(t, Param::kShadeMismatch)) < 0.05 &&
        std::fabs(at(f, Param::kShadeElevationRad) - at(t, Param::kShadeElevationRad)) < 0.02 &&
        std::fabs(at(f, Param::kShadeAzimuthRad) + 0.5 * at(f, Param::kShadeWidthRad) -
                  at(t, Param::kShadeAzimuthRad) - 0.5 * at(t, Param::kShadeWidthRad)) < 0.03;
    found += ok ? 1 : 0;
    if (!ok) misses += "seed " + std::to_string(seed) + ": " + fit.summary.BriefReport() + "\n";
  }
  std::printf("shading: obstacle found from the reference start on %d of data seeds 101-112\n",
              found);
  EXPECT_GE(found, 10) << misses;
}

INSTANTIATE_TEST_SUITE_P(
    AllEffects, EffectIdentification,
    ::testing::Values(IdentCase{"capacitance", "1Nwr", Param::kCPvJM2K, 5e3, 101},
                      // U_coll: started 8× above the truth; the fit returns 17.1
                      // (truth 12) with a standard error of 29 % (0.021 of the
                      // log range): tolerance 9 ≈ 2 standard errors. With the
                      // default tolerances the fit stops at 26, hence
                      // converge_fully. The base model's gap is 0.058 W/m²
                      // (2.3 noise standard errors): not well above the noise
                      // at U_coll = 12.
                      IdentCase{"second_node", "1N1Cwr", Param::kUCollWM2K, 9.0, 102, 100.0,
                                /*converge_fully=*/true, /*gap_visible=*/false},
                      IdentCase{"wind", "1N1Cr", Param::kRRefWind, 0.01, 103},
                      IdentCase{"sky_radiation", "1N1Cw", Param::kEpsPvt, 0.02, 104},
                      IdentCase{"iam", "1N1Cwr", Param::kEtaPvRef, 0.005, 105},
                      // The base model absorbs this effect into r0/r1: its
                      // held-out MAE is 1.325 against a floor of 1.300 W/m²
                      // (1 noise standard error); no gap is required.
                      IdentCase{"flow_dependent_u", "1N1Cwr", Param::kNFlow, 0.2, 106,
                                std::numeric_limits<double>::quiet_NaN(),
                                /*converge_fully=*/false, /*gap_visible=*/false},
                      IdentCase{"transport_delay", "1N1Cwr", Param::kTransportDelayS, 30.0, 107},
                      IdentCase{"pv_clipping", "1N1Cwr", Param::kPLimitWM2, 2.0, 108},
                      IdentCase{"shading", "1N1Cwr", Param::kShadeMismatch, 0.05, 109},
                      IdentCase{"soiling", "1N1Cwr", Param::kSoilingPerDay, 0.001, 110},
                      IdentCase{"clock_offset", "1N1Cwr", Param::kClockOffsetS, 60.0, 111},
                      IdentCase{"irradiance_bias", "1N1Cwr", Param::kEtaPvRef, 0.005, 112}),
    [](const ::testing::TestParamInfo<IdentCase>& info) { return std::string(info.param.effect); });

}  // namespace
}  // namespace pvtwin
