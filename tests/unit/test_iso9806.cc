// ISO 9806 equivalents of the grey-box model (core/fit/iso9806.h), checked
// against the model itself at operating points the read-off did not use, and
// against the structure of each variant.
#include <gtest/gtest.h>

#include <cmath>

#include "core/fit/iso9806.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

// The model's steady thermal efficiency Q_u/(A·G) and ϑm − ϑa at constant
// conditions (1000 W/m² of beam at normal incidence, ambient 25 °C).
std::pair<double, double> Steady(const Plant& plant, const ModelSpec& spec, const ParamVector& p,
                                 double t_in_c, double wind_m_s) {
  testing::ConstantInputs in;
  in.g_poa_w_m2 = 1000.0;
  in.t_in_c = t_in_c;
  in.t_amb_c = in.t_back_c = in.t_sky_c = 25.0;
  in.wind_m_s = wind_m_s;
  in.mdot_kg_s = 0.03;
  Series s = testing::MakeConstantSeries(48, 900.0, in);
  testing::AddPoaDiffuse(&s, 0.0);
  s[Channel::kAoiRad].assign(s.size(), 0.0);
  Drivers d;
  std::string error;
  EXPECT_TRUE(PrepareDrivers(s, plant, spec, &d, &error)) << error;
  SimOutputs out;
  Simulate(d, p, &out);
  const std::size_t last = s.size() - 1;
  return {out.q_th_w[last] / (plant.area_m2 * 1000.0), 0.5 * (t_in_c + out.t_out_c[last]) - 25.0};
}

TEST(Iso9806, TheLinePredictsTheModelAtAThirdTemperature) {
  const Plant plant = DesignExamplePlant();
  for (const char* name : {"1N", "2N1Ccolwr", "2N2Cwr", "1N1Cr+wind"}) {
    const ModelSpec spec = testing::SpecOf(name);
    const ParamVector p = TruthParamsFor(plant, spec);
    const Iso9806Equivalents iso = Iso9806EquivalentsOf(plant, spec, p, 0.03, 3.0);
    ASSERT_TRUE(iso.ok) << name;
    // 60 °C at the inlet was not one of the two read-off points (20, 45 °C).
    const auto [eta, dt_m_k] = Steady(plant, spec, p, 60.0, 3.0);
    // The model's loss is linear in ϑm − ϑa up to its sky term (linearised
    // about T_PV) and the PV efficiency's temperature term: within 1 % of η0.
    EXPECT_NEAR(iso.eta0 - iso.loss_w_m2k * dt_m_k / 1000.0, eta, 0.01 * iso.eta0) << name;
    EXPECT_GT(iso.eta0, 0.2) << name;
    EXPECT_LT(iso.eta0, 0.9) << name;
    EXPECT_GT(iso.loss_w_m2k, 1.0) << name;
  }
}

TEST(Iso9806, EachCoefficientComesFromItsPartOfTheModel) {
  const Plant plant = DesignExamplePlant();
  const auto iso_of = [&](const char* name) {
    const ModelSpec spec = testing::SpecOf(name);
    return Iso9806EquivalentsOf(plant, spec, TruthParamsFor(plant, spec), 0.03, 3.0);
  };
  // No wind law, no sky term: c3 = c6 = c4 = 0.
  const Iso9806Equivalents plain = iso_of("1N");
  EXPECT_NEAR(plain.c3_j_m3k, 0.0, 1e-9);
  EXPECT_NEAR(plain.c6_s_m, 0.0, 1e-12);
  EXPECT_NEAR(plain.c4, 0.0, 1e-9);
  EXPECT_EQ(plain.c5_j_m2k, 0.0);
  // The physical wind form adds loss with wind: c3 > 0, c6 > 0.
  const Iso9806Equivalents wind = iso_of("1N+wind");
  EXPECT_GT(wind.c3_j_m3k, 0.1);
  EXPECT_GT(wind.c6_s_m, 0.0);
  // Sky radiation: a colder sky takes heat, c4 in (0, 1).
  const Iso9806Equivalents sky = iso_of("1Nr");
  EXPECT_GT(sky.c4, 0.01);
  EXPECT_LT(sky.c4, 1.0);
  // Capacitances: c5 is the sum of the nodes'.
  const ModelSpec two_c = testing::SpecOf("2N2Cwr");
  const ParamVector p = TruthParamsFor(plant, two_c);
  EXPECT_DOUBLE_EQ(Iso9806EquivalentsOf(plant, two_c, p, 0.03).c5_j_m2k,
                   p[static_cast<std::size_t>(Param::kCPvJM2K)] +
                       p[static_cast<std::size_t>(Param::kCCollJM2K)]);
}

}  // namespace
}  // namespace pvtwin
