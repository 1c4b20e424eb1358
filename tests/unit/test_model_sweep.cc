// Robustness of every variant across Table 3's parameter bounds and data
// steps from 5 s to 15 min, and a structural check of which parameters each
// variant's outputs depend on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/common/units.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

// Six hours of a varying day: irradiance ramps and cloud steps, changing inlet
// temperature and flow including pump stops, gusty wind. From 06:00 UTC on
// 2024-06-01 (07:04 local solar time at the design example's site), with
// 30 % diffuse in the clear hours and all diffuse under the cloud, so that
// the 'I' variant has a real sun path and a beam/diffuse split.
Series VaryingSeries(double step_s) {
  const std::size_t rows = static_cast<std::size_t>(6 * 3600 / step_s);
  Series s = testing::MakeConstantSeries(rows, step_s, {}, testing::kJune1_2024UtcS + 6 * 3600);
  s[Channel::kGPoaDiffuseWM2].resize(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    const double t_h = static_cast<double>(i) * step_s / 3600.0;
    const bool cloud = std::fmod(t_h, 1.0) > 0.7;
    s[Channel::kGPoaWM2][i] = 950.0 * std::sin(kPi * (t_h + 0.5) / 7.0) * (cloud ? 0.3 : 1.0);
    s[Channel::kGPoaDiffuseWM2][i] = (cloud ? 1.0 : 0.3) * s[Channel::kGPoaWM2][i];
    s[Channel::kTInC][i] = 15.0 + 30.0 * t_h / 6.0;
    s[Channel::kMdotKgS][i] = std::fmod(t_h, 2.0) < 0.25 ? 0.0 : 0.02 + 0.02 * (t_h / 6.0);
    s[Channel::kWindMS][i] = 3.0 + 2.5 * std::sin(7.0 * t_h);
    s[Channel::kTAmbC][i] = 18.0 + 4.0 * t_h / 6.0;
    s[Channel::kTSkyC][i] = 2.0;
    s[Channel::kTBackC][i] = 20.0;
  }
  return s;
}

Drivers DriversOf(const Series& s, const Plant& plant, const ModelSpec& spec) {
  Drivers d;
  std::string error;
  EXPECT_TRUE(PrepareDrivers(s, plant, spec, &d, &error)) << error;
  return d;
}

std::vector<std::string> AllTestedVariants() {
  std::vector<std::string> v = PaperVariants();  // 2N1CcolwrI included
  // Appended from one list: four push_backs of literals drew a false
  // -Wstringop-overread from GCC 12's link-time optimisation.
  const std::vector<std::string> more = {"2N1Ccolr", "1N1Cr+wind", "2N2C+wind+transport_delay",
                                         "1N1Cwr+flow_dependent_u+pv_clipping+soiling"};
  v.insert(v.end(), more.begin(), more.end());
  return v;
}

ParamVector DrawParams(const Plant& plant, std::mt19937_64& rng, int mode) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  ParamVector p{};
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo info = ResolvedInfo(static_cast<Param>(i), plant);
    const double f = mode == 0 ? 0.0 : mode == 1 ? 1.0 : u01(rng);
    p[i] = info.scale == ParamScale::kLog
               ? std::exp(std::log(info.lower) + f * (std::log(info.upper) - std::log(info.lower)))
               : info.lower + f * (info.upper - info.lower);
  }
  return p;
}

TEST(ModelSweep, FiniteAndBoundedAcrossBoundsAndSteps) {
  const Plant plant = DesignExamplePlant();
  std::mt19937_64 rng(7);
  for (double step_s : {5.0, 60.0, 300.0, 900.0}) {
    const Series s = VaryingSeries(step_s);
    double t_min = 1e9, t_max = -1e9, g_max = 0.0;
    for (Channel c : {Channel::kTInC, Channel::kTAmbC, Channel::kTSkyC, Channel::kTBackC}) {
      for (double v : s[c]) {
        t_min = std::min(t_min, v);
        t_max = std::max(t_max, v);
      }
    }
    for (double g : s[Channel::kGPoaWM2]) g_max = std::max(g_max, g);
    for (const std::string& v : AllTestedVariants()) {
      const ModelSpec spec = testing::SpecOf(v);
      const Drivers d = DriversOf(s, plant, spec);
      if (spec.iam) {  // the sun geometry is there: the IAM takes a share of the beam
        double g_abs_sum = 0.0, g_poa_sum = 0.0;
        for (std::size_t i = 0; i < d.size(); ++i) {
          g_abs_sum += d.g_abs_w_m2[i];
          g_poa_sum += d.g_poa_w_m2[i];
        }
        ASSERT_TRUE(std::isfinite(g_abs_sum)) << v;
        EXPECT_LT(g_abs_sum, 0.99 * g_poa_sum) << v;
      }
      SimOutputs out;
      for (int sample = 0; sample < 12; ++sample) {
        const ParamVector p = DrawParams(plant, rng, std::min(sample, 2));
        Simulate(d, p, &out);
        // Minimum principle: with non-negative absorbed heat no node falls
        // below the coldest boundary temperature. Upper bound: all absorbed
        // heat must leave through the front or through U_coll and U_back in
        // series (the weakest paths).
        auto at = [&p](Param x) { return p[static_cast<std::size_t>(x)]; };
        const double u_front_min = 1.0 / (1.0 / at(Param::kUFrontWM2K) +
                                          at(Param::kRRefWind) * std::pow(5.5, at(Param::kNWind)));
        const double u_path =
            spec.nodes == 2 ? 1.0 / (1.0 / at(Param::kUCollWM2K) + 1.0 / at(Param::kUBackWM2K))
                            : at(Param::kUBackWM2K);
        const double t_upper = t_max + at(Param::kFTh) * g_max / (u_front_min + u_path) + 1.0;
        for (std::size_t i = 0; i < s.size(); ++i) {
          for (double t : {out.t_pv_c[i], out.t_coll_c[i]}) {
            ASSERT_TRUE(std::isfinite(t)) << v << " step " << step_s << " sample " << sample;
            ASSERT_GE(t, t_min - 1e-6) << v << " step " << step_s << " sample " << sample;
            ASSERT_LE(t, t_upper) << v << " step " << step_s << " sample " << sample;
          }
          ASSERT_TRUE(std::isfinite(out.q_th_w[i]) && std::isfinite(out.t_out_c[i]));
          ASSERT_GE(out.p_el_w[i], 0.0);
          ASSERT_LE(out.p_el_w[i], at(Param::kAreaM2) * s[Channel::kGPoaWM2][i] + 1e-9);
        }
      }
    }
  }
}

// A variant's outputs change with every parameter it uses and with no other.
TEST(ModelSweep, OutputsDependOnExactlyTheUsedParameters) {
  const Plant plant = DesignExamplePlant();
  const Series s = VaryingSeries(60.0);
  for (const std::string& v : AllTestedVariants()) {
    const ModelSpec spec = testing::SpecOf(v);
    const Drivers d = DriversOf(s, plant, spec);
    const ParamVector base = StartParams(plant);
    SimOutputs ref, out;
    Simulate(d, base, &ref);
    const auto used = UsedParams(spec);
    for (std::size_t i = 0; i < kNumParams; ++i) {
      ParamVector p = base;
      p[i] *= 1.3;
      if (p[i] == 0.0) p[i] = 0.1;
      Simulate(d, p, &out);
      double change = 0.0;
      for (std::size_t r = 0; r < s.size(); ++r) {
        change +=
            std::fabs(out.p_el_w[r] - ref.p_el_w[r]) + std::fabs(out.q_th_w[r] - ref.q_th_w[r]);
      }
      if (used.test(i)) {
        EXPECT_GT(change, 1e-6) << v << " should depend on " << kParamTable[i].name;
      } else {
        EXPECT_EQ(change, 0.0) << v << " should not depend on " << kParamTable[i].name;
      }
    }
  }
}

}  // namespace
}  // namespace pvtwin
