// Each effect of the library on an analytic case: the effect moves the
// outputs in the predicted direction by the predicted amount
// (core/effects/effects.h, thermal_model.cc, drivers.cc).
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/units.h"
#include "core/effects/effects.h"
#include "core/effects/flow_dependent_u.h"
#include "core/effects/iam.h"
#include "core/model/thermal_model.h"
#include "core/physics/iam.h"
#include "core/physics/irradiance.h"
#include "core/synth/synthetic_plant.h"
#include "core/synth/weather_generator.h"
#include "tests/support/effect_named.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

double& At(ParamVector& p, Param name) { return p[static_cast<std::size_t>(name)]; }

Drivers DriversOf(const Series& s, const Plant& plant, const std::string& variant) {
  Drivers d;
  std::string error;
  EXPECT_TRUE(PrepareDrivers(s, plant, testing::SpecOf(variant), &d, &error)) << error;
  return d;
}

SimOutputs SimulateWith(const Drivers& d, const ParamVector& p, bool energy = false) {
  SimOutputs out;
  SimOptions options;
  options.energy_terms = energy;
  Simulate(d, p, &out, options);
  return out;
}

// Parameters with a constant PV efficiency (no temperature or irradiance
// correction), so that P_el = η_ref·A·I exactly.
ParamVector ConstantEta(const Plant& plant) {
  ParamVector p = ReferenceTruthParams(plant);
  At(p, Param::kPvTempCoeffPerK) = 0.0;
  At(p, Param::kPvIrrCoeffM2W) = 0.0;
  return p;
}

// One summer day of generated weather at the doc/contracts.md plant (sun geometry,
// beam and diffuse), sampled every 10 min.
Series SummerDay() {
  WeatherOptions w;
  w.num_days = 1;
  w.step_s = 600.0;
  w.seed = 3;
  w.day_types = {DayType::kClear};
  return GenerateWeather(DesignExamplePlant(), w);
}

// pv_clipping caps P_el exactly at P_limit·A; the clipped power stays in the
// laminate: Q_abs = F_th·(A·I − P_el), so Q_u and T_PV rise.
TEST(EffectModel, ClippingCapsPelAtTheLimitAndKeepsTheRestAsHeat) {
  const Plant plant;
  testing::ConstantInputs in;
  in.g_poa_w_m2 = 1000.0;
  const Series s = testing::MakeConstantSeries(30, 60.0, in);
  ParamVector p = ConstantEta(plant);
  At(p, Param::kPLimitWM2) = 100.0;  // below η·I = 170 W/m²
  const SimOutputs base = SimulateWith(DriversOf(s, plant, "1N1C"), p, true);
  const SimOutputs clip = SimulateWith(DriversOf(s, plant, "1N1C+pv_clipping"), p, true);
  const double area = At(p, Param::kAreaM2);
  const double f_th = At(p, Param::kFTh);
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(base.p_el_w[i], 0.17 * area * 1000.0, 1e-9);
    EXPECT_DOUBLE_EQ(clip.p_el_w[i], 100.0 * area);
    EXPECT_NEAR(clip.q_abs_w[i], f_th * (area * 1000.0 - 100.0 * area), 1e-9);
    EXPECT_GT(clip.q_th_w[i], base.q_th_w[i]);
    EXPECT_GT(clip.t_pv_c[i], base.t_pv_c[i]);
  }
  // A limit above the DC power changes nothing.
  At(p, Param::kPLimitWM2) = 250.0;
  const SimOutputs high = SimulateWith(DriversOf(s, plant, "1N1C+pv_clipping"), p);
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(high.p_el_w[i], base.p_el_w[i], 1e-9);
    EXPECT_NEAR(high.q_th_w[i], base.q_th_w[i], 1e-9);
  }
}

// shading removes the beam only while the sun is inside the window, and
// the share of the sky diffuse the box hides on every row: with the window
// around the sun the absorbed irradiance is the unhidden diffuse part and
// P_el additionally loses f_mismatch; with the window on the opposite side
// only the hidden sky is lost.
TEST(EffectModel, ShadingRemovesBeamOnlyInsideTheWindowAndHitsPelHarder) {
  const Plant plant = DesignExamplePlant();
  const Series s = SummerDay();
  const Drivers base_d = DriversOf(s, plant, "1N");
  const Drivers shade_d = DriversOf(s, plant, "1N+shading");
  ParamVector p = ConstantEta(plant);
  const SimOutputs base = SimulateWith(base_d, p, true);
  const double area = At(p, Param::kAreaM2);
  const double mismatch = 0.5;
  At(p, Param::kShadeMismatch) = mismatch;
  At(p, Param::kShadeWidthRad) = kPi;            // ±90° around the centre
  At(p, Param::kShadeElevationRad) = kPi / 2.0;  // every elevation
  // A wall up to the zenith over half the azimuths hides half the sky.
  const double hidden = 0.5;
  int inside = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[Channel::kGPoaWM2][i] < 200.0) continue;
    const double beam = s[Channel::kGPoaWM2][i] - s[Channel::kGPoaDiffuseWM2][i];
    ASSERT_GT(beam, 50.0);
    // Window centred on the sun of this row.
    At(p, Param::kShadeAzimuthRad) = shade_d.sun_azimuth_rad[i];
    const SimOutputs in = SimulateWith(shade_d, p, true);
    const double diffuse = s[Channel::kGPoaDiffuseWM2][i];
    EXPECT_NEAR(in.p_el_w[i], 0.17 * area * diffuse * (1.0 - hidden) * (1.0 - mismatch),
                1e-3 * base.p_el_w[i]);
    // P_el loses the beam share, the hidden sky and the mismatch; the
    // absorbed heat loses less than the beam and the hidden sky (the
    // mismatch power stays as heat).
    const double beam_share = beam / s[Channel::kGPoaWM2][i];
    const double light_lost = beam_share + hidden * (1.0 - beam_share);
    const double p_drop = 1.0 - in.p_el_w[i] / base.p_el_w[i];
    const double q_abs_drop = 1.0 - in.q_abs_w[i] / base.q_abs_w[i];
    EXPECT_NEAR(p_drop, light_lost + mismatch * (1.0 - light_lost), 1e-3) << "row " << i;
    EXPECT_LT(q_abs_drop, light_lost) << "row " << i;
    EXPECT_GT(q_abs_drop, 0.0) << "row " << i;
    if (s[Channel::kMdotKgS][i] > 0.0) {
      EXPECT_LT(in.q_th_w[i], base.q_th_w[i]) << "row " << i;
    }
    // Window on the opposite side of the sky: the beam stays, the hidden sky
    // does not, and no substring is dropped.
    At(p, Param::kShadeAzimuthRad) = shade_d.sun_azimuth_rad[i] + kPi;
    const SimOutputs out = SimulateWith(shade_d, p);
    EXPECT_NEAR(out.p_el_w[i], 0.17 * area * (s[Channel::kGPoaWM2][i] - hidden * diffuse),
                1e-9 * base.p_el_w[i]);
    ++inside;
  }
  EXPECT_GE(inside, 30);
  // An obstacle below the sun shades nothing.
  At(p, Param::kShadeAzimuthRad) = kPi;
  At(p, Param::kShadeElevationRad) = 0.0;
  const SimOutputs low = SimulateWith(shade_d, p);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (shade_d.sun_elevation_rad[i] > DegToRad(20.0)) {
      EXPECT_NEAR(low.p_el_w[i], base.p_el_w[i], 1e-6 * base.p_el_w[i] + 1e-9);
    }
  }
}

// Ten days, hourly, at 800 W/m², a constant efficiency and a soiling rate
// of 1 % a day: the soiling tests' plant.
struct SoilingCase {
  static constexpr std::size_t rows = 10 * 24;
  static constexpr double rate = 0.01;
  Plant plant;
  Series s;
  ParamVector p;
  Drivers d;
  double area;
  SoilingCase() {
    testing::ConstantInputs in;
    in.g_poa_w_m2 = 800.0;
    s = testing::MakeConstantSeries(rows, 3600.0, in);
    p = ConstantEta(plant);
    At(p, Param::kSoilingPerDay) = rate;
    d = DriversOf(s, plant, "1N+soiling");
    area = At(p, Param::kAreaM2);
  }
  // P_el = η·A·G·(1 − loss), η = 0.17 (ConstantEta: η_PV,ref of the truth).
  double PEl(double loss) const { return 0.17 * area * 800.0 * (1.0 - loss); }
};

// soiling: P_el = η·A·I·(1 − r·d), d the days since the last cleaning; a
// cleaning resets d.
TEST(EffectModel, SoilingGrowsLinearlyAndCleaningResetsIt) {
  SoilingCase c;
  SimOutputs out = SimulateWith(c.d, c.p);
  for (std::size_t i = 0; i < c.rows; ++i) {
    const double days = static_cast<double>(i) / 24.0;
    EXPECT_NEAR(out.p_el_w[i], c.PEl(c.rate * days), 1e-9) << i;
  }
  const std::int64_t rain_s = c.s.time_s[0] + 4 * 86400 + 1800;  // mid-row on day 4
  SetCleaningTimes({rain_s}, &c.d);
  out = SimulateWith(c.d, c.p);
  for (std::size_t i = 0; i < c.rows; ++i) {
    const double t = static_cast<double>(c.s.time_s[i]);
    const double days = t < static_cast<double>(rain_s)
                            ? (t - static_cast<double>(c.s.time_s[0])) / 86400.0
                            : (t - static_cast<double>(rain_s)) / 86400.0;
    EXPECT_NEAR(out.p_el_w[i], c.PEl(c.rate * days), 1e-9) << i;
  }
}

// A cleaning the data show lowers the loss by its recovery from then on:
// τ = 1 − max(0, r·d − recovered), never above 1.
TEST(EffectModel, SoilingDropsByTheRecoveryOfACleaningSeenInTheData) {
  SoilingCase c;
  const std::int64_t wash_s = c.s.time_s[0] + 4 * 86400;
  SetCleanings({{wash_s, 0.03}}, &c.d);
  const SimOutputs out = SimulateWith(c.d, c.p);
  for (std::size_t i = 0; i < c.rows; ++i) {
    const double days = static_cast<double>(i) / 24.0;
    const double loss = std::max(0.0, c.rate * days - (c.s.time_s[i] >= wash_s ? 0.03 : 0.0));
    EXPECT_NEAR(out.p_el_w[i], c.PEl(loss), 1e-9) << i;
  }
}

// DetectCleanings on twelve days at 10 min (6 bright hours a day at
// 800 W/m², T_PV 25 °C so that PI = P_el/g_poa): the performance falls 1 %
// a day with ±0.3 % day-to-day scatter; a rain at the start of day 7 gives
// back 5 % (found, with its recovery); a single good day on day 3 that the
// next day undoes is not a cleaning; without P_el nothing is found.
TEST(Cleanings, FoundWhereThePerformanceRecoversAndStays) {
  const Plant plant;  // longitude 0: solar days start at 00:00 UTC
  testing::ConstantInputs in;
  const std::int64_t t0 = 1'717'200'000;  // 2024-06-01 00:00 UTC
  Series s = testing::MakeConstantSeries(12 * 144, 600.0, in, t0);
  s[Channel::kTPvC].assign(s.size(), 25.0);
  std::vector<double>& g = s[Channel::kGPoaWM2];
  std::vector<double>& p_el = s[Channel::kPElW];
  p_el.assign(s.size(), 0.0);
  std::vector<double> index(12);
  for (int day = 0; day < 12; ++day) {
    double level = 0.3 * (1.0 - 0.01 * day) * (1.0 + 0.003 * std::sin(1.7 * day));
    if (day >= 7) level *= 1.05;
    if (day == 3) level *= 1.04;
    index[static_cast<std::size_t>(day)] = level;
  }
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::size_t day = i / 144, in_day = i % 144;
    const bool bright = in_day >= 54 && in_day < 90;  // 09:00–15:00
    g[i] = bright ? 800.0 : 0.0;
    p_el[i] = bright ? index[day] * 800.0 : 0.0;
  }
  const std::vector<Cleaning> found = DetectCleanings(s, plant);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].time_s, t0 + 7 * 86400);
  EXPECT_NEAR(found[0].recovered, index[7] / index[6] - 1.0, 1e-12);
  Series no_power = s;
  no_power[Channel::kPElW].clear();
  EXPECT_TRUE(DetectCleanings(no_power, plant).empty());
}

// clock_offset by a whole number of rows equals the base model on inputs
// whose weather columns are shifted by those rows (a model without
// capacitance: each row depends on its own inputs only).
TEST(EffectModel, ClockOffsetEqualsTheBaseModelOnShiftedWeather) {
  const Plant plant = DesignExamplePlant();
  const Series s = SummerDay();
  const auto n = static_cast<long>(s.size());
  for (const long shift_rows : {2L, -1L}) {  // weather clock behind / ahead
    ParamVector p = ReferenceTruthParams(plant);
    At(p, Param::kClockOffsetS) = static_cast<double>(shift_rows) * s.step_s;
    const SimOutputs shifted_model = SimulateWith(DriversOf(s, plant, "1Nwr+clock_offset"), p);
    Series moved = s;
    for (Channel c : {Channel::kGPoaWM2, Channel::kTAmbC, Channel::kWindMS, Channel::kLwDownWM2,
                      Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2}) {
      for (long i = 0; i < n; ++i) {
        const long j = i + shift_rows;
        if (j >= 0 && j < n)
          moved[c][static_cast<std::size_t>(i)] = s[c][static_cast<std::size_t>(j)];
      }
    }
    const SimOutputs base_on_moved = SimulateWith(DriversOf(moved, plant, "1Nwr"), p);
    int compared = 0;
    for (long i = std::max(0L, -shift_rows); i < std::min(n, n - shift_rows); ++i) {
      const auto r = static_cast<std::size_t>(i);
      EXPECT_NEAR(shifted_model.p_el_w[r], base_on_moved.p_el_w[r], 1e-9) << shift_rows << " " << i;
      EXPECT_NEAR(shifted_model.q_th_w[r], base_on_moved.q_th_w[r], 1e-7) << shift_rows << " " << i;
      compared += s[Channel::kGPoaWM2][r] > 100.0;
    }
    EXPECT_GT(compared, 40);
  }
}

// flow_dependent_u: 1/U_fluid = r1/(2w) + r0·(w_ref/w)^n. Without sun the
// one-node balance is G_f·(T_in − T) + G_loss·(T_amb − T) = 0, so
// Q_u = G_f·G_loss/(G_f + G_loss)·(T_amb − T_in) with G_f = U_fluid·A.
TEST(EffectModel, FlowDependentUFollowsTheFlowPowerLaw) {
  const Plant plant;
  ParamVector p = ReferenceTruthParams(plant);
  const double area = At(p, Param::kAreaM2);
  const double r0 = 0.05, r1 = At(p, Param::kR1Fluid), n_flow = 0.8;
  At(p, Param::kR0FluidM2KW) = r0;
  At(p, Param::kNFlow) = n_flow;
  const double g_loss_w_k = (At(p, Param::kUFrontWM2K) + At(p, Param::kUBackWM2K)) * area;
  for (double flow_factor : {0.25, 0.5, 1.0, 2.0}) {
    testing::ConstantInputs in;
    in.t_in_c = 40.0;
    in.t_amb_c = 10.0;
    in.t_back_c = 10.0;
    in.mdot_kg_s = kFlowReferenceKgSM2 * area * flow_factor;
    const Series s = testing::MakeConstantSeries(5, 60.0, in);
    const SimOutputs out = SimulateWith(DriversOf(s, plant, "1N+flow_dependent_u"), p);
    const double w = in.mdot_kg_s * plant.fluid_cp_j_kgk / area;
    const double u_fluid = 1.0 / (r1 / (2.0 * w) + r0 * std::pow(1.0 / flow_factor, n_flow));
    const double g_f = u_fluid * area;
    const double expected = g_f * g_loss_w_k / (g_f + g_loss_w_k) * (in.t_amb_c - in.t_in_c);
    EXPECT_NEAR(out.q_th_w[4], expected, 1e-9 * std::fabs(expected)) << flow_factor;
    const SimOutputs base = SimulateWith(DriversOf(s, plant, "1N"), p);
    if (flow_factor == 1.0) {
      EXPECT_NEAR(out.q_th_w[4], base.q_th_w[4], 1e-9);
    }
    // Below the reference flow the convective resistance grows: less heat
    // exchanged than the laminar form predicts, above it more.
    if (flow_factor < 1.0) {
      EXPECT_LT(std::fabs(out.q_th_w[4]), std::fabs(base.q_th_w[4]));
    }
    if (flow_factor > 1.0) {
      EXPECT_GT(std::fabs(out.q_th_w[4]), std::fabs(base.q_th_w[4]));
    }
  }
}

// transport_delay's pipe loss: at steady state the sensor sees
// T_amb + (T_out − T_amb)·exp(−U_pipe·A/(ṁ·c_p)); the dead time delays a step.
TEST(EffectModel, TransportDelayCoolsTheOutletInThePipeAndDelaysSteps) {
  const Plant plant;
  testing::ConstantInputs in;
  in.g_poa_w_m2 = 700.0;
  in.mdot_kg_s = 0.02;
  Series s = testing::MakeConstantSeries(60, 60.0, in);
  for (std::size_t i = 30; i < 60; ++i) s[Channel::kTInC][i] = 35.0;  // inlet step at row 30
  ParamVector p = ReferenceTruthParams(plant);
  const double area = At(p, Param::kAreaM2);
  At(p, Param::kUPipeWM2K) = 2.0;
  At(p, Param::kTransportDelayS) = 180.0;  // three rows
  const SimOutputs base = SimulateWith(DriversOf(s, plant, "1N"), p);
  const SimOutputs pipe = SimulateWith(DriversOf(s, plant, "1N+transport_delay"), p);
  const double decay = std::exp(-2.0 * area / (in.mdot_kg_s * plant.fluid_cp_j_kgk));
  for (std::size_t i : {std::size_t{20}, std::size_t{29}, std::size_t{50}}) {
    const double t_sensor = in.t_amb_c + (base.t_out_c[i] - in.t_amb_c) * decay;
    EXPECT_NEAR(pipe.t_out_c[i], t_sensor, 1e-9) << i;
    EXPECT_NEAR(pipe.q_th_w[i],
                in.mdot_kg_s * plant.fluid_cp_j_kgk * (t_sensor - s[Channel::kTInC][i]), 1e-6);
    EXPECT_LT(pipe.q_th_w[i], base.q_th_w[i]);
  }
  // Rows 30–32 still see the outlet of the old inlet temperature.
  for (std::size_t i = 30; i < 33; ++i) {
    EXPECT_NEAR(pipe.t_out_c[i], in.t_amb_c + (base.t_out_c[29] - in.t_amb_c) * decay, 1e-9);
  }
}

// transport_delay's second form, the pipe as a volume ("+pipe_volume"). A
// plug of 3.6 kg at 0.02 kg/s: a row of 60 s moves 1.2 kg, the row's middle
// leaves the plug 3 rows later; at 0.04 kg/s (2.4 kg a row) 1.5 rows later,
// midway between two rows' outlets: the lag scales with 1/flow. A mixed 2.4 kg at 0.02 kg/s is a
// first-order lag of 120 s: after an inlet step the sensor's row means follow T_new + (T_end,prev −
// T_new)·(1 − e^(−1/2))/(1/2). With a loss UA and no mass, steady state: (ṁ·c_p·T_out +
// UA·T_amb)/(ṁ·c_p + UA).
TEST(EffectModel, PipeVolumeDelaysByMassOverFlowAndMixesAsATank) {
  const Plant plant;
  testing::ConstantInputs in;
  in.g_poa_w_m2 = 700.0;
  for (double mdot : {0.02, 0.04}) {
    in.mdot_kg_s = mdot;
    Series s = testing::MakeConstantSeries(60, 60.0, in);
    for (std::size_t i = 30; i < 60; ++i) s[Channel::kTInC][i] = 35.0;  // inlet step at row 30
    ParamVector p = ReferenceTruthParams(plant);
    const double area = At(p, Param::kAreaM2);
    At(p, Param::kUPipeWM2K) = 0.0;
    At(p, Param::kPipePlugKgM2) = 3.6 / area;
    At(p, Param::kPipeMixKgM2) = 0.0;
    const SimOutputs base = SimulateWith(DriversOf(s, plant, "1N"), p);
    const Drivers pipe_d = DriversOf(s, plant, "1N+pipe_volume");
    const SimOutputs plug = SimulateWith(pipe_d, p);
    for (std::size_t i = 25; i < 40; ++i) {
      // 0.04 kg/s: a lag of 1.5 rows, between the rows' middles.
      const double seen =
          mdot == 0.02 ? base.t_out_c[i - 3] : 0.5 * (base.t_out_c[i - 1] + base.t_out_c[i - 2]);
      EXPECT_NEAR(plug.t_out_c[i], seen, 1e-9) << mdot << " row " << i;
      EXPECT_NEAR(plug.q_th_w[i],
                  mdot * plant.fluid_cp_j_kgk * (plug.t_out_c[i] - s[Channel::kTInC][i]), 1e-6);
    }
    if (mdot != 0.02) continue;
    At(p, Param::kPipePlugKgM2) = 0.0;
    At(p, Param::kPipeMixKgM2) = 2.4 / area;
    const SimOutputs mixed = SimulateWith(pipe_d, p);
    const double a = base.t_out_c[29], b = base.t_out_c[30];
    const double decay = std::exp(-0.5), mean_factor = (1.0 - decay) / 0.5;
    double t_end = a;
    for (std::size_t i = 30; i < 40; ++i) {
      EXPECT_NEAR(mixed.t_out_c[i], b + (t_end - b) * mean_factor, 1e-9) << "row " << i;
      t_end = b + (t_end - b) * decay;
    }
    At(p, Param::kPipeMixKgM2) = 0.0;
    At(p, Param::kUPipeWM2K) = 2.0;
    const SimOutputs lossy = SimulateWith(pipe_d, p);
    const double flow_w_k = mdot * plant.fluid_cp_j_kgk, ua = 2.0 * area;
    EXPECT_NEAR(lossy.t_out_c[50],
                (flow_w_k * base.t_out_c[50] + ua * in.t_amb_c) / (flow_w_k + ua), 1e-9);
  }
}

// iam's fitted form "+iam": the absorbed irradiance is each part of the
// in-plane irradiance (paper 2.5's split of the measured g_poa and its
// diffuse) weighted with ASHRAE's K = 1 − b0·(1/cos θ − 1) at its angle
// instead of the paper's τα; with a constant efficiency P_el = η·A·I_at, so
// the ratio of P_el is the ratio of the weighted sums, by hand per row.
TEST(EffectModel, FittedIamReweightsEachPartWithAshraesModifier) {
  const Plant plant = DesignExamplePlant();
  const Series s = SummerDay();
  const Drivers paper_d = DriversOf(s, plant, "1NI");
  const Drivers fit_d = DriversOf(s, plant, "1NI+iam");
  ParamVector p = ConstantEta(plant);
  const double b0 = 0.12;
  At(p, Param::kIamB0Fit) = b0;
  const SimOutputs paper = SimulateWith(paper_d, p);
  const SimOutputs fit = SimulateWith(fit_d, p);
  const EffectiveDiffuseAngles angles = BrandemuehlBeckmanAngles(plant.tilt_rad);
  auto ashrae = [b0](double theta) {
    return std::max(0.0, 1.0 - b0 * (1.0 / std::cos(theta) - 1.0));
  };
  int rows = 0, grazing = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!(s[Channel::kGPoaWM2][i] > 20.0)) continue;
    MeasuredPoaInput m;
    m.g_poa_w_m2 = s[Channel::kGPoaWM2][i];
    m.g_poa_diffuse_w_m2 = s[Channel::kGPoaDiffuseWM2][i];
    m.ghi_w_m2 = s.At(Channel::kGhiWM2, i);
    m.dhi_w_m2 = s.At(Channel::kDhiWM2, i);
    m.tilt_rad = plant.tilt_rad;
    m.ground_albedo = plant.ground_albedo;
    const PoaComponents poa = SplitMeasuredPoa(m);
    const double theta = paper_d.aoi_rad[i];
    const double by_hand = (theta < 0.5 * kPi ? ashrae(theta) * poa.beam_w_m2 : 0.0) +
                           ashrae(angles.sky_rad) * poa.sky_diffuse_w_m2 +
                           ashrae(angles.ground_rad) * poa.ground_diffuse_w_m2;
    const double paper_sum = AbsorbedIrradianceWM2(poa, theta, angles, plant.iam_b0);
    EXPECT_NEAR(fit.p_el_w[i] / paper.p_el_w[i], by_hand / paper_sum, 1e-9) << "row " << i;
    ++rows;
    if (theta > DegToRad(60.0) && poa.beam_w_m2 > 10.0) ++grazing;
  }
  EXPECT_GE(rows, 40);
  EXPECT_GE(grazing, 3);  // rows where the paper's linear segment and ASHRAE differ
}

// irradiance_bias: the scale error of a plane-of-array sensor that reads 6 %
// low is found from the transposed GHI/DHI, and the model with the effect
// sees the true irradiance again.
TEST(EffectModel, IrradianceBiasIsCalibratedAgainstTheSecondSource) {
  const Plant plant = DesignExamplePlant();
  WeatherOptions w;
  w.num_days = 2;
  w.step_s = 300.0;
  w.seed = 5;
  const Series truth = GenerateWeather(plant, w);
  Series biased = truth;
  for (double& g : biased[Channel::kGPoaWM2]) g /= 1.06;
  for (double& g : biased[Channel::kGPoaDiffuseWM2]) g /= 1.06;
  const Drivers d = DriversOf(biased, plant, "1N+irradiance_bias");
  EXPECT_NEAR(d.irradiance_bias, 0.06, 0.01);
  const Drivers unbiased = DriversOf(truth, plant, "1N");
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_NEAR(d.g_poa_w_m2[i], unbiased.g_poa_w_m2[i], 0.01 * unbiased.g_poa_w_m2[i] + 1e-9);
  }
  // The base model's drivers keep the signature: reference − measured > 0.
  const Drivers base = DriversOf(biased, plant, "1N");
  const std::vector<double> sig =
      EffectSignature(testing::EffectNamed("irradiance_bias"), base, SimOutputs{});
  double sum = 0.0;
  for (std::size_t i = 0; i < sig.size(); ++i) {
    if (base.g_poa_w_m2[i] > 300.0) sum += sig[i] / base.g_poa_w_m2[i];
  }
  EXPECT_GT(sum, 0.0);
  // Without a second source the variant cannot be prepared.
  Series poa_only = biased;
  poa_only[Channel::kGhiWM2].clear();
  poa_only[Channel::kDhiWM2].clear();
  Drivers none;
  std::string error;
  EXPECT_FALSE(
      PrepareDrivers(poa_only, plant, testing::SpecOf("1N+irradiance_bias"), &none, &error));
  EXPECT_NE(error.find("ghi_w_m2 + dhi_w_m2"), std::string::npos) << error;
}

}  // namespace
}  // namespace pvtwin
