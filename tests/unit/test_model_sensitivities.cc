// The model run with sensitivities (core/model/sensitivities.h) against
// central differences of Simulate, for every Table 6 variant at random
// parameter points inside the bounds and for every registered effect form
// at points around the reference plant (recorded seeds), on three days of
// synthetic weather with the pump going on and off; and the RC step's
// tangent against the analytic step response. Where the central
// differences are not limited by rounding the two agree to about 1e-9 of
// the column's scale; the tests hold 1e-6. Leaving out the derivatives of
// the linearisation point (sensitivities.h) fails them (errors 1e-4 … 5e-2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/effects/registry.h"
#include "core/model/sensitivities.h"
#include "core/model/thermal_model.h"
#include "core/physics/rc_network_tangent.h"
#include "core/synth/synthetic_plant.h"
#include "core/synth/weather_generator.h"

namespace pvtwin {
namespace {

// Every used parameter with a search range at a uniform position in the
// middle 60 % of its unit coordinate (log where the range spans decades).
ParamVector RandomPoint(const Plant& plant, const ModelSpec& spec, std::mt19937_64* rng) {
  ParamVector p = TruthParamsFor(plant, spec);
  std::uniform_real_distribution<double> u(0.2, 0.8);
  const auto used = UsedParams(spec);
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo info = ResolvedInfo(static_cast<Param>(i), plant);
    if (!used.test(i) || !(info.upper > info.lower)) continue;
    const double z = u(*rng);
    p[i] = info.scale == ParamScale::kLog ? info.lower * std::pow(info.upper / info.lower, z)
                                          : info.lower + z * (info.upper - info.lower);
  }
  return p;
}

// Every used parameter with a search range moved from the reference truth
// (TruthParamsFor) by up to ±0.15 of its unit coordinate, inside [0.05,
// 0.95]: a plant whose PV node stays in η_PV's linear range. (RandomPoint's
// whole box also holds a nearly insulated PV node at 200 °C, where η_PV is
// clamped at 0 on most sunny rows.)
ParamVector PointNearTruth(const Plant& plant, const ModelSpec& spec, std::mt19937_64* rng) {
  ParamVector p = TruthParamsFor(plant, spec);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  const auto used = UsedParams(spec);
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo info = ResolvedInfo(static_cast<Param>(i), plant);
    if (!used.test(i) || !(info.upper > info.lower)) continue;
    const bool log = info.scale == ParamScale::kLog;
    const double z0 = log ? std::log(p[i] / info.lower) / std::log(info.upper / info.lower)
                          : (p[i] - info.lower) / (info.upper - info.lower);
    const double z = std::clamp(z0 + u(*rng), 0.05, 0.95);
    p[i] = log ? info.lower * std::pow(info.upper / info.lower, z)
               : info.lower + z * (info.upper - info.lower);
  }
  return p;
}

// The used parameters with a search range, A_PVT and the PV coefficients
// included (identification may free them).
std::vector<Param> UsedWithRange(const Plant& plant, const ModelSpec& spec) {
  std::vector<Param> wrt;
  const auto used = UsedParams(spec);
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo info = ResolvedInfo(static_cast<Param>(i), plant);
    if (used.test(i) && info.upper > info.lower) wrt.push_back(static_cast<Param>(i));
  }
  return wrt;
}

struct Comparison {
  double worst = 0.0;  // largest relative error over columns and outputs
  std::string where;
  int kinks = 0;  // rows × columns × outputs left out as not smooth
  // Rows × outputs whose value differs from Simulate's: the run with
  // sensitivities does Simulate's arithmetic in Simulate's order, so a
  // caller may take its values for a plain run of the same parameters.
  int values_differing = 0;
};

// max_i |exact − central| / max_i |central| per column and output, beyond
// the rounding floor of the central differences (100·ε·max|output|/h). The
// central step is h = 1e-5 of the parameter (truncation ~1e-10 relative).
// A row where the central differences with steps h and h/2 disagree by more
// than 0.5e-6 is not smooth within ±h (the linearisation's pass count
// changes there: a jump that grows like 1/h in the difference quotient, and
// travels on with the node states) and is counted in `kinks` instead.
Comparison Compare(const Drivers& d, const ParamVector& p, const std::vector<Param>& wrt) {
  Comparison c;
  SimSensitivities sens;
  EXPECT_TRUE(SimulateSensitivities(d, p, wrt, &sens));
  SimOutputs plain;
  Simulate(d, p, &plain);
  const std::size_t n = d.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double pairs[3][2] = {{sens.p_el_w[i], plain.p_el_w[i]},
                                {sens.q_th_w[i], plain.q_th_w[i]},
                                {sens.t_pv_c[i], plain.t_pv_c[i]}};
    for (const auto& v : pairs) {
      if (std::isnan(v[0]) && std::isnan(v[1])) continue;
      if (!(v[0] == v[1])) ++c.values_differing;
    }
  }
  const std::vector<double> SimOutputs::*fields[] = {&SimOutputs::p_el_w, &SimOutputs::q_th_w,
                                                     &SimOutputs::t_pv_c};
  const std::vector<double>* exact[] = {&sens.dp_el_w, &sens.dq_th_w, &sens.dt_pv_c};
  const char* names[] = {"p_el_w", "q_th_w", "t_pv_c"};
  for (std::size_t j = 0; j < wrt.size(); ++j) {
    const auto idx = static_cast<std::size_t>(wrt[j]);
    const double h = 1e-5 * std::fabs(p[idx]);
    SimOutputs runs[4];  // p + h, p − h, p + h/2, p − h/2
    const double steps[4] = {h, -h, 0.5 * h, -0.5 * h};
    for (int k = 0; k < 4; ++k) {
      ParamVector q = p;
      q[idx] += steps[k];
      Simulate(d, q, &runs[k]);
    }
    for (int o = 0; o < 3; ++o) {
      const auto& f = fields[o];
      double scale = 0.0, magnitude = 0.0;
      std::vector<double> d1(n), d2(n);
      for (std::size_t i = 0; i < n; ++i) {
        d1[i] = ((runs[0].*f)[i] - (runs[1].*f)[i]) / (2.0 * h);
        d2[i] = ((runs[2].*f)[i] - (runs[3].*f)[i]) / h;
        if (std::isnan(d2[i])) continue;
        scale = std::max(scale, std::fabs(d2[i]));
        magnitude = std::max(magnitude, std::fabs((plain.*f)[i]));
      }
      const double floor = 100.0 * 2.2e-16 * magnitude / h;
      double diff = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double ad = (*exact[o])[j * n + i];
        if (std::isnan(d2[i]) && std::isnan(ad)) continue;
        if (std::fabs(d1[i] - d2[i]) > 0.5e-6 * scale + floor) {
          ++c.kinks;
          continue;
        }
        diff = std::max(diff, std::fabs(ad - d1[i]) - floor);
        if (std::isnan(ad)) diff = INFINITY;
      }
      const double rel = scale > 0.0 ? std::max(diff, 0.0) / scale : diff;
      if (!(rel <= c.worst)) {
        c.worst = rel;
        c.where = std::string(Info(wrt[j]).name) + " on " + names[o];
      }
    }
  }
  return c;
}

Series TestWeather(const Plant& plant) {
  WeatherOptions w;
  w.num_days = 3;
  w.step_s = 300.0;
  w.seed = 11;
  w.flow_mode = FlowMode::kVariable;  // pump on and off
  return GenerateWeather(plant, w);
}

// `days` days at 1 min, the pump on and off.
Series MinuteWeather(const Plant& plant, int days) {
  WeatherOptions w;
  w.num_days = days;
  w.step_s = 60.0;
  w.seed = 5;
  w.flow_mode = FlowMode::kVariable;
  return GenerateWeather(plant, w);
}

Drivers TestDrivers(const std::string& variant, const Series& s, const Plant& plant) {
  ModelSpec spec;
  std::string error;
  EXPECT_TRUE(ParseVariant(variant, &spec, &error)) << error;
  Drivers d;
  EXPECT_TRUE(PrepareDrivers(s, plant, spec, &d, &error)) << error;
  return d;
}

TEST(ModelSensitivities, Table6VariantsMatchCentralDifferences) {
  const Plant plant = DesignExamplePlant();
  const Series s = TestWeather(plant);
  int tested = 0;
  for (const std::string& variant : PaperVariants()) {
    const Drivers d = TestDrivers(variant, s, plant);
    const std::vector<Param> wrt = UsedWithRange(plant, d.spec);
    if (!SensitivitiesSupported(d.spec, wrt, nullptr)) continue;
    ++tested;
    std::mt19937_64 rng(2026);
    for (int point = 0; point < 4; ++point) {
      const ParamVector p = RandomPoint(plant, d.spec, &rng);
      const Comparison c = Compare(d, p, wrt);
      EXPECT_EQ(c.values_differing, 0) << variant << ", point " << point;
      EXPECT_LE(c.worst, 1e-6) << variant << ", point " << point << ": " << c.where;
      // Non-smooth rows are rare: at most 1 % of rows × columns × outputs.
      EXPECT_LE(c.kinks, static_cast<int>(3 * wrt.size() * d.size() / 100))
          << variant << ", point " << point;
    }
  }
  EXPECT_EQ(tested, 9);  // all of Table 6
}

// At 1 min, the step of the identification's fine stage.
TEST(ModelSensitivities, OneMinuteStepMatchesCentralDifferences) {
  const Plant plant = DesignExamplePlant();
  const Series s = MinuteWeather(plant, 2);
  for (const std::string variant : {"1N1Cwr", "2N1Ccolwr", "2N1Cpvwr", "2N2Cwr"}) {
    const Drivers d = TestDrivers(variant, s, plant);
    const std::vector<Param> wrt = UsedWithRange(plant, d.spec);
    std::mt19937_64 rng(7);
    const Comparison c = Compare(d, RandomPoint(plant, d.spec, &rng), wrt);
    EXPECT_EQ(c.values_differing, 0) << variant;
    EXPECT_LE(c.worst, 1e-6) << variant << ": " << c.where;
  }
}

// Every form in which the diagnosis adds a registered effect to 2N1Ccolwr
// (EffectModule::add_to_spec and diagnosis_forms), as variant names, plus
// the electric effects together (P_el clipped after the shading and soiling
// factors).
std::vector<std::string> EffectVariants() {
  std::vector<std::string> out;
  for (const EffectModule* m : EffectRegistry()) {
    std::vector<void (*)(ModelSpec*)> forms;
    for (const EffectForm& f : m->diagnosis_forms) forms.push_back(f.add);
    if (m->add_to_spec != nullptr) forms.push_back(m->add_to_spec);
    std::vector<ModelSpec> specs;
    for (auto* add : forms) {
      ModelSpec spec;
      std::string error;
      EXPECT_TRUE(ParseVariant("2N1Ccolwr", &spec, &error)) << error;
      add(&spec);
      specs.push_back(spec);
    }
    if (m->add_to_spec == nullptr && m->extension != nullptr) {
      ModelSpec spec;
      std::string error;
      EXPECT_TRUE(ParseVariant("2N1Ccolwr", &spec, &error)) << error;
      spec.Add(*m->extension);
      specs.push_back(spec);
    }
    for (const ModelSpec& spec : specs) {
      if (spec.extensions.empty()) continue;  // a letter: Table6VariantsMatchCentralDifferences
      if (std::find(out.begin(), out.end(), spec.Name()) == out.end()) out.push_back(spec.Name());
    }
  }
  out.push_back("2N1Ccolwr+pv_clipping+shading+soiling");
  return out;
}

// The parameters of UsedWithRange that no effect hook reads: the columns a
// run with sensitivities gives (HookParams).
std::vector<Param> SensitivityColumns(const Plant& plant, const ModelSpec& spec) {
  return WithoutHookParams(spec, UsedWithRange(plant, spec));
}

// Issue 16: the run with sensitivities of every effect that changes the
// run's inputs, electric effects included, against central differences at
// random points, for the parameters no hook reads (a base parameter a hook
// reads but does not declare in reads_base_params shows up here as a wrong
// column). Every hook parameter makes the spec unsupported (the caller
// differences it). transport_delay's sensor behind a pipe transforms the
// outputs: its derivatives are pushed through the hook (outputs_affine),
// which these differences check as well. Non-smooth points: where P_el meets the inverter limit
// (its derivatives jump to zero), a shading window's edges (the sun
// crossing them moves with the effect's parameters only, which are
// differenced) and the pump switching on or off (data, the same for every
// parameter); `kinks` counts the rows × columns × outputs left out there.
TEST(ModelSensitivities, EffectVariantsMatchCentralDifferences) {
  const Plant plant = DesignExamplePlant();
  const Series s = TestWeather(plant);
  int tested = 0, clipped_rows = 0;
  std::string names;
  const std::vector<std::string> variants = EffectVariants();
  for (const std::string& variant : variants) {
    const Drivers d = TestDrivers(variant, s, plant);
    const std::vector<Param> wrt = SensitivityColumns(plant, d.spec);
    std::string why;
    if (!SensitivitiesSupported(d.spec, wrt, &why)) {
      ADD_FAILURE() << variant << ": " << why;
      continue;
    }
    for (Param p : HookParams(d.spec)) {
      const std::vector<Param> one = {p};
      EXPECT_FALSE(SensitivitiesSupported(d.spec, one, nullptr)) << variant << " " << Info(p).name;
    }
    ++tested;
    names += variant + " ";
    std::mt19937_64 rng(2027);
    for (int point = 0; point < 3; ++point) {
      ParamVector p = PointNearTruth(plant, d.spec, &rng);
      // An inverter limit that the sunniest hours exceed: 85 % of the peak.
      ParamVector unlimited = p;
      unlimited[static_cast<std::size_t>(Param::kPLimitWM2)] = 1e9;
      SimOutputs peak;
      Simulate(d, unlimited, &peak);
      const double peak_w = *std::max_element(peak.p_el_w.begin(), peak.p_el_w.end(),
                                              [](double a, double b) { return !(b <= a); });
      p[static_cast<std::size_t>(Param::kPLimitWM2)] = 0.85 * peak_w / ParamOf(p, Param::kAreaM2);
      const Comparison c = Compare(d, p, wrt);
      EXPECT_EQ(c.values_differing, 0) << variant << ", point " << point;
      EXPECT_LE(c.worst, 1e-6) << variant << ", point " << point << ": " << c.where;
      EXPECT_LE(c.kinks, static_cast<int>(3 * wrt.size() * d.size() / 100))
          << variant << ", point " << point;
      if (variant.find("pv_clipping") == std::string::npos) continue;
      SimOutputs out;
      Simulate(d, p, &out);
      const double limit_w = ParamOf(p, Param::kPLimitWM2) * ParamOf(p, Param::kAreaM2);
      for (double p_el : out.p_el_w) clipped_rows += p_el == limit_w ? 1 : 0;
    }
  }
  std::printf("effect variants with sensitivities: %s\n", names.c_str());
  // Every form, transport_delay's two affine output transforms included.
  EXPECT_EQ(tested, static_cast<int>(variants.size())) << names;
  EXPECT_GE(tested, 12) << names;
  EXPECT_GT(clipped_rows, 20);  // the clipped rows' derivatives were compared
}

// Without the T_PV derivatives (an objective without T_PV) the run writes
// the same P_el and Q_u derivatives to the bit and leaves dt_pv_c empty;
// with an extension that transforms the outputs, the transform takes every
// output's derivatives, and the run keeps T_PV's.
TEST(ModelSensitivities, TheTPvDerivativesAreLeftOutOnlyWhenNoTransformReadsThem) {
  const Plant plant = DesignExamplePlant();
  const Series s = TestWeather(plant);
  for (const std::string variant : {"2N1Ccolwr", "1N1Cwr+transport_delay"}) {
    const Drivers d = TestDrivers(variant, s, plant);
    const std::vector<Param> wrt = SensitivityColumns(plant, d.spec);
    std::mt19937_64 rng(11);
    const ParamVector p = PointNearTruth(plant, d.spec, &rng);
    SimSensitivities all, without;
    without.t_pv_derivatives = false;
    ASSERT_TRUE(SimulateSensitivities(d, p, wrt, &all)) << variant;
    ASSERT_TRUE(SimulateSensitivities(d, p, wrt, &without)) << variant;
    ASSERT_EQ(all.dt_pv_c.size(), d.size() * wrt.size()) << variant;
    const bool transforms = variant.find("transport_delay") != std::string::npos;
    EXPECT_EQ(without.dt_pv_c.size(), transforms ? all.dt_pv_c.size() : 0u) << variant;
    for (auto field : {&SimSensitivities::dp_el_w, &SimSensitivities::dq_th_w,
                       &SimSensitivities::p_el_w, &SimSensitivities::t_pv_c}) {
      const std::vector<double>& a = all.*field;
      const std::vector<double>& b = without.*field;
      ASSERT_EQ(a.size(), b.size()) << variant;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::isnan(a[i]) && std::isnan(b[i])) continue;
        ASSERT_EQ(a[i], b[i]) << variant << " at " << i;
      }
    }
  }
}

// With the columns split over two threads the run writes every value and
// every derivative as on one, to the bit and NaN for NaN: variants of each
// two-node network shape (one node's runs are not split), an odd number of
// columns, an electric effect and an output transform (which then reads
// all the derivatives).
TEST(ModelSensitivities, TwoThreadsGiveTheSameRunToTheBit) {
  const Plant plant = DesignExamplePlant();
  const Series s = MinuteWeather(plant, 10);
  for (const std::string variant :
       {"2Nwr", "2N1Cpvwr", "2N1Ccolwr", "2N2Cwr", "2N1Ccolwr+transport_delay",
        "2N1Ccolwr+pv_clipping+shading+soiling"}) {
    const Drivers d = TestDrivers(variant, s, plant);
    const std::vector<Param> wrt = SensitivityColumns(plant, d.spec);
    ASSERT_GE(d.size() * wrt.size(), kSensitivitySplitWork) << variant << ": not split";
    std::mt19937_64 rng(3);
    const ParamVector p = PointNearTruth(plant, d.spec, &rng);
    SimSensitivities one, two;
    two.threads = 2;
    ASSERT_TRUE(SimulateSensitivities(d, p, wrt, &one)) << variant;
    ASSERT_TRUE(SimulateSensitivities(d, p, wrt, &two)) << variant;
    for (auto field :
         {&SimSensitivities::p_el_w, &SimSensitivities::q_th_w, &SimSensitivities::t_pv_c,
          &SimSensitivities::dp_el_w, &SimSensitivities::dq_th_w, &SimSensitivities::dt_pv_c,
          &SimSensitivities::t_coll_c, &SimSensitivities::t_out_c, &SimSensitivities::dt_coll_c,
          &SimSensitivities::dt_out_c}) {
      const std::vector<double>& a = one.*field;
      const std::vector<double>& b = two.*field;
      ASSERT_EQ(a.size(), b.size()) << variant;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::isnan(a[i]) && std::isnan(b[i])) continue;
        ASSERT_EQ(a[i], b[i]) << variant << " at " << i << " of " << a.size();
      }
    }
    EXPECT_EQ(one.dt_pv_c.size(), d.size() * wrt.size()) << variant;
    // Every column has derivatives: the second share's are not left at zero.
    for (std::size_t j = 0; j < wrt.size(); ++j) {
      double largest = 0.0;
      for (std::size_t i = 0; i < d.size(); ++i) {
        const double v = std::fabs(two.DQTh(j)[i]) + std::fabs(two.DTPv(j)[i]);
        if (std::isfinite(v)) largest = std::max(largest, v);
      }
      EXPECT_GT(largest, 0.0) << variant << ", column " << Info(wrt[j]).name;
    }
  }
}

// With a sink the run writes each derivative scaled into the caller's
// matrix at the caller's rows, to the bit what the stored derivatives give
// (the sink's arithmetic order), on one thread and on two, and flags a
// column with a non-finite entry; rows the sink has no place for and the
// matrix's other columns stay untouched. An output transform reads the
// stored derivatives: the run then keeps them and leaves the sink alone.
TEST(ModelSensitivities, ASinkTakesTheScaledDerivativesAtItsRows) {
  const Plant plant = DesignExamplePlant();
  const Series s = MinuteWeather(plant, 10);
  for (const std::string variant : {"2N1Ccolwr", "1N1Cwr", "1N1Cwr+transport_delay"}) {
    Drivers d = TestDrivers(variant, s, plant);
    d.usable[700] = 0;  // a row without a result (a gap in the data)
    const std::vector<Param> wrt = SensitivityColumns(plant, d.spec);
    std::mt19937_64 rng(7);
    const ParamVector p = PointNearTruth(plant, d.spec, &rng);
    SimSensitivities stored;
    ASSERT_TRUE(SimulateSensitivities(d, p, wrt, &stored)) << variant;
    ASSERT_FALSE(stored.in_sink);
    // The sink's columns are wrt's reversed, one to the right (column 0 is
    // the caller's own).
    const std::size_t cols = wrt.size() + 1;
    std::vector<std::size_t> column(wrt.size());
    std::vector<double> factor(wrt.size());
    for (std::size_t j = 0; j < wrt.size(); ++j) {
      column[j] = wrt.size() - j;
      factor[j] = 0.5 + 0.25 * static_cast<double>(j);
    }
    // The sink's rows: every third row with a result, in order; then also
    // the first row without one (every column non-finite).
    std::size_t no_result = d.size();
    for (std::size_t i = 0; i < d.size() && no_result == d.size(); ++i) {
      if (std::isnan(stored.q_th_w[i])) no_result = i;
    }
    ASSERT_LT(no_result, d.size()) << variant << ": the data have no row without a result";
    for (int threads : {1, 2, -1}) {
      std::vector<std::int32_t> position(d.size(), -1);
      std::size_t rows = 0;
      for (std::size_t i = 0; i < d.size(); ++i) {
        if ((i % 3 == 0 && !std::isnan(stored.q_th_w[i])) || (threads < 0 && i == no_result)) {
          position[i] = static_cast<std::int32_t>(rows++);
        }
      }
      const double kUntouched = -12345.0;
      std::vector<double> matrix(3 * rows * cols, kUntouched);
      SensitivitySink sink;
      sink.base = matrix.data();
      sink.stride = 3 * rows;
      sink.rows = rows;
      sink.position = position;
      sink.column = column;
      sink.column_factor = factor;
      sink.value_factor = 1.0 / 1.8;
      sink.t_pv_factor = 5.0;
      SimSensitivities run;
      run.sink = &sink;
      run.threads = std::abs(threads);
      ASSERT_TRUE(SimulateSensitivities(d, p, wrt, &run)) << variant;
      const bool transforms = variant.find("transport_delay") != std::string::npos;
      EXPECT_EQ(run.in_sink, !transforms) << variant;
      for (std::size_t i = 0; i < d.size(); ++i) {
        if (std::isnan(stored.q_th_w[i])) continue;
        ASSERT_EQ(run.q_th_w[i], stored.q_th_w[i]) << variant << " row " << i;
        ASSERT_EQ(run.p_el_w[i], stored.p_el_w[i]) << variant << " row " << i;
      }
      if (transforms) {
        ASSERT_EQ(run.dq_th_w.size(), stored.dq_th_w.size()) << variant;
        for (std::size_t i = 0; i < stored.dq_th_w.size(); ++i) {
          if (std::isnan(stored.dq_th_w[i]) && std::isnan(run.dq_th_w[i])) continue;
          ASSERT_EQ(run.dq_th_w[i], stored.dq_th_w[i]) << variant << " at " << i;
        }
        EXPECT_TRUE(std::all_of(matrix.begin(), matrix.end(), [&](double v) {
          return v == kUntouched;
        })) << variant;
        continue;
      }
      EXPECT_TRUE(run.dp_el_w.empty() && run.dq_th_w.empty() && run.dt_pv_c.empty()) << variant;
      ASSERT_EQ(sink.finite.size(), wrt.size());
      for (std::size_t j = 0; j < wrt.size(); ++j) {
        const double* col = matrix.data() + column[j] * sink.stride;
        bool finite = true;
        for (std::size_t i = 0; i < d.size(); ++i) {
          if (position[i] < 0) continue;
          const auto k = static_cast<std::size_t>(position[i]);
          const double vp = stored.DPEl(j)[i] * sink.value_factor * factor[j];
          const double vq = stored.DQTh(j)[i] * sink.value_factor * factor[j];
          const double vt = sink.t_pv_factor * stored.DTPv(j)[i] * factor[j];
          finite = finite && std::isfinite(vp) && std::isfinite(vq) && std::isfinite(vt);
          if (!std::isfinite(vp)) continue;  // a row without a result
          ASSERT_EQ(col[k], vp) << variant << " column " << j << " row " << i;
          ASSERT_EQ(col[rows + k], vq) << variant << " column " << j << " row " << i;
          ASSERT_EQ(col[2 * rows + k], vt) << variant << " column " << j << " row " << i;
        }
        EXPECT_EQ(sink.finite[j] != 0, finite) << variant << " column " << j;
        EXPECT_EQ(finite, threads > 0) << variant << " column " << j;
      }
      // The caller's own column.
      EXPECT_TRUE(std::all_of(matrix.begin(), matrix.begin() + static_cast<long>(sink.stride),
                              [&](double v) { return v == kUntouched; }))
          << variant;
    }
  }
}

TEST(ModelSensitivities, UnsupportedSpecsSayWhy) {
  const Plant plant = DesignExamplePlant();
  for (const std::string variant : {"1N1Cr+wind", "2N2Cwr+transport_delay"}) {
    ModelSpec spec;
    std::string error;
    ASSERT_TRUE(ParseVariant(variant, &spec, &error)) << error;
    const std::vector<Param> wrt = UsedWithRange(plant, spec);
    std::string why;
    EXPECT_FALSE(SensitivitiesSupported(spec, wrt, &why)) << variant;
    EXPECT_NE(why.find("finite differences"), std::string::npos) << why;
  }
}

// One capacitive node from T0 towards T∞ = S/G: T(dt) = T∞ + (T0 − T∞)·e^(−G·dt/C),
// so dT/dC = (T0 − T∞)·e^(−G·dt/C)·G·dt/C² and dT/dS = (1 − e^(−G·dt/C))/G.
TEST(RcNetworkTangent, OneNodeStepResponse) {
  RcNetwork net;
  net.node[0] = {2.0e4, 15.0, 15.0 * 40.0};  // C, G, S: T∞ = 40 °C
  const double t0[2] = {10.0, 0.0};
  const double dt = 300.0;
  const RcStepResult value = AdvanceRcShaped<RcShape::kOneCapacitive>(net, t0, dt);
  RcNetworkTangent d{};
  d.directions = 2;
  d.capacitance_j_k[0][0] = 1.0;  // direction 0: C
  d.source_w[0][1] = 1.0;         // direction 1: S
  RcStepTangent out;
  AdvanceRcTangent<RcShape::kOneCapacitive>(net, t0, dt, value, d, &out);
  const double decay = std::exp(-15.0 * dt / 2.0e4);
  EXPECT_NEAR(value.t_end_c[0], 40.0 + (10.0 - 40.0) * decay, 1e-12);
  EXPECT_NEAR(out.t_end_c[0][0], (10.0 - 40.0) * decay * 15.0 * dt / (2.0e4 * 2.0e4), 1e-15);
  EXPECT_NEAR(out.t_end_c[0][1], (1.0 - decay) / 15.0, 1e-15);
}

}  // namespace
}  // namespace pvtwin
