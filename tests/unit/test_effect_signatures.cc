// The effects' signature checks (EffectModule::shows_signature) and their
// helper BestLag on data whose answer is known by construction: a signal
// shifted by a known number of rows, a measured P_el that stops at an
// inverter limit and one that does not; and the advice sentences with the
// fitted values (EffectModule::advice_for).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/common/units.h"
#include "core/effects/effect_module.h"
#include "core/effects/pv_clipping.h"
#include "core/effects/shading.h"
#include "core/effects/transport_delay.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

// n rows at 60 s, all usable, one stretch; rows 0 … n−1 are objective rows.
Drivers SignatureRows(std::size_t n, std::vector<std::uint32_t>* rows) {
  Drivers d;
  d.plant.area_m2 = 2.0;
  for (std::size_t i = 0; i < n; ++i) {
    d.time_s.push_back(static_cast<std::int64_t>(60 * i));
    d.restart.push_back(i == 0 ? 1 : 0);
    d.usable.push_back(1);
    rows->push_back(static_cast<std::uint32_t>(i));
  }
  return d;
}

TEST(BestLag, FindsTheShiftOfARandomWalkInEitherDirection) {
  std::vector<std::uint32_t> rows;
  const Drivers d = SignatureRows(600, &rows);
  std::mt19937 rng(3);
  std::normal_distribution<double> step(0.0, 1.0);
  std::vector<double> pred(600, 0.0), late(600, 0.0), early(600, 0.0);
  for (std::size_t i = 1; i < 600; ++i) pred[i] = pred[i - 1] + step(rng);
  for (std::size_t i = 0; i < 600; ++i) {
    late[i] = i >= 2 ? pred[i - 2] + 5.0 : pred[0] + 5.0;  // follows 2 rows later, biased
    early[i] = i + 3 < 600 ? pred[i + 3] : pred[599];      // 3 rows ahead
  }
  const LagFit l = BestLag(d, rows, late, pred, -5, 5);
  EXPECT_EQ(l.lag_rows, 2);
  EXPECT_GT(l.corr_at_lag, 0.99);
  EXPECT_LT(l.corr_at_zero, 0.2);
  EXPECT_EQ(BestLag(d, rows, early, pred, -5, 5).lag_rows, -3);
  // A restart in every row leaves no unbroken pairs to correlate.
  Drivers broken = d;
  for (std::size_t i = 0; i < 600; ++i) broken.restart[i] = 1;
  EXPECT_EQ(BestLag(broken, rows, late, pred, -5, 5).pairs, 0u);
}

// A bell-shaped DC power up to 300 W on 2 m²; measured = min(DC, 200 W)
// with 0.5 W noise for a clipping inverter, = DC for one that does not clip.
TEST(PvClippingSignature, APlateauAtTheFittedLimitIsShownAndMissingWithoutOne) {
  std::vector<std::uint32_t> rows;
  const Drivers d = SignatureRows(720, &rows);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.5);
  SimOutputs before, after;
  std::vector<double> clipped(720), unclipped(720), q(720, 0.0);
  ParamVector params{};
  params[static_cast<std::size_t>(Param::kPLimitWM2)] = 100.0;  // 200 W on 2 m²
  params[static_cast<std::size_t>(Param::kAreaM2)] = 2.0;
  for (std::size_t i = 0; i < 720; ++i) {
    const double x = (static_cast<double>(i) - 360.0) / 150.0;
    const double dc = 300.0 * std::exp(-x * x);
    before.p_el_w.push_back(dc);
    after.p_el_w.push_back(std::min(dc, 200.0));
    clipped[i] = std::min(dc, 200.0) + noise(rng);
    unclipped[i] = dc + noise(rng);
  }
  before.q_th_w = after.q_th_w = q;
  SignatureData s;
  s.drivers = &d;
  s.rows = &rows;
  s.q_th_meas_w = &q;
  s.before = &before;
  s.after = &after;
  s.params = &params;
  s.p_el_meas_w = &clipped;
  const SignatureCheck shown = PvClippingEffect().shows_signature(s);
  EXPECT_TRUE(shown.shown) << shown.sentence;
  EXPECT_NE(shown.sentence.find("200 W"), std::string::npos) << shown.sentence;
  s.p_el_meas_w = &unclipped;
  const SignatureCheck missing = PvClippingEffect().shows_signature(s);
  EXPECT_FALSE(missing.shown) << missing.sentence;
}

// A τ below half the row step cannot show as a lag: transport_delay is then
// not shown, with or without a pipe loss (a τ of a few seconds merely
// smooths the outlet between rows; a pipe loss alone is one more thermal
// loss, which the same-form battery's second node had been taken for).
TEST(TransportDelaySignature, ASubStepDelayIsNotShown) {
  std::vector<std::uint32_t> rows;
  Drivers d = SignatureRows(100, &rows);
  d.spec = testing::SpecOf("1N1Cwr+transport_delay");
  SimOutputs out;
  out.q_th_w.assign(100, 0.0);
  std::vector<double> q(100, 0.0);
  ParamVector params{};
  params[static_cast<std::size_t>(Param::kTransportDelayS)] = 2.0;
  params[static_cast<std::size_t>(Param::kUPipeWM2K)] = 0.0;
  SignatureData s;
  s.drivers = &d;
  s.rows = &rows;
  s.q_th_meas_w = s.p_el_meas_w = &q;
  s.before = s.after = &out;
  s.params = &params;
  const SignatureCheck none = TransportDelayEffect().shows_signature(s);
  EXPECT_FALSE(none.shown) << none.sentence;
  EXPECT_NE(none.sentence.find("below half the 60 s row step"), std::string::npos) << none.sentence;
  params[static_cast<std::size_t>(Param::kUPipeWM2K)] = 0.4;
  const SignatureCheck loss = TransportDelayEffect().shows_signature(s);
  EXPECT_FALSE(loss.shown) << loss.sentence;
  // A delay of 3 rows whose model the measured changes follow is shown.
  params[static_cast<std::size_t>(Param::kTransportDelayS)] = 180.0;
  std::vector<double> pred(100), late(100);
  for (std::size_t i = 0; i < 100; ++i) pred[i] = std::sin(0.37 * i) + 0.2 * std::sin(1.9 * i);
  for (std::size_t i = 0; i < 100; ++i) late[i] = i >= 3 ? pred[i - 3] : pred[0];
  SimOutputs before, after;
  before.q_th_w = pred;
  after.q_th_w = late;
  s.before = &before;
  s.after = &after;
  s.q_th_meas_w = &late;
  const SignatureCheck lag = TransportDelayEffect().shows_signature(s);
  EXPECT_TRUE(lag.shown) << lag.sentence;
}

// Advice in the site's units from the fitted parameters: 120 W/m² on 1.8 m²
// is 216 W; an obstacle centred at 250° with a 40° width reaches 230–270°.
TEST(EffectAdvice, SaysTheFittedValuesInPhysicalUnits) {
  Plant plant;
  plant.area_m2 = 1.8;
  ParamVector p{};
  p[static_cast<std::size_t>(Param::kPLimitWM2)] = 120.0;
  EXPECT_EQ(PvClippingEffect()
                .advice_for(ModelSpec{}, p, plant)
                .rfind("Inverter limit ≈ 216 W (120 W/m²)", 0),
            0u);
  p[static_cast<std::size_t>(Param::kShadeAzimuthRad)] = 250.0 * kPi / 180.0;
  p[static_cast<std::size_t>(Param::kShadeWidthRad)] = 40.0 * kPi / 180.0;
  p[static_cast<std::size_t>(Param::kShadeElevationRad)] = 25.0 * kPi / 180.0;
  EXPECT_NE(ShadingEffect()
                .advice_for(ModelSpec{}, p, plant)
                .find("azimuth 230–270°, up to 25° elevation"),
            std::string::npos)
      << ShadingEffect().advice_for(ModelSpec{}, p, plant);
  // The pipe as a volume: 1.0 + 0.5 kg/m² on 1.8 m² is 2.7 kg, 2.6 L at
  // 1040 kg/m³.
  p[static_cast<std::size_t>(Param::kAreaM2)] = 1.8;
  p[static_cast<std::size_t>(Param::kPipePlugKgM2)] = 1.0;
  p[static_cast<std::size_t>(Param::kPipeMixKgM2)] = 0.5;
  const std::string pipe =
      TransportDelayEffect().advice_for(testing::SpecOf("1N1Cwr+pipe_volume"), p, plant);
  EXPECT_NE(pipe.find("2.6 L of pipe (1.8 kg in plug flow, 0.9 kg mixed"), std::string::npos)
      << pipe;
  p[static_cast<std::size_t>(Param::kTransportDelayS)] = 95.0;
  EXPECT_NE(TransportDelayEffect()
                .advice_for(testing::SpecOf("1N1Cwr+transport_delay"), p, plant)
                .find("95 s late"),
            std::string::npos);
}

}  // namespace
}  // namespace pvtwin
