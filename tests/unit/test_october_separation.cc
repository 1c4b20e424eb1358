// Why the October other-form cases miss (issue 52): where the truth's effect
// acts, measured on the self-test's own data. For a case and seed the
// footprint of the effect is the truth's noise-free output of the null case
// (the same weather, operation and seed without the effect) minus the
// case's; it is split by what separates the candidates at low sun: morning
// against afternoon (an IAM acts on both sides of solar noon alike, an
// obstacle in the west only in the afternoon), the angle of incidence, beam
// against diffuse light, and for the obstacle the days it stands on.
// Development seeds only (1–3, 101–103); the figures go to doc/validation.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/common/calendar.h"
#include "core/common/units.h"
#include "core/diagnosis/diagnosis_selftest.h"
#include "core/effects/shading.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/seeds.h"

namespace pvtwin {
namespace {

const SelftestCase& CaseNamed(const std::vector<SelftestCase>& cases, const std::string& name) {
  for (const SelftestCase& c : cases) {
    if (c.name == name) return c;
  }
  ADD_FAILURE() << "no case " << name;
  return cases.front();
}

// Footprint energy (Wh, P_el + Q_th) of one case and seed, split.
struct Footprint {
  double total_wh = 0.0;
  double afternoon_wh = 0.0;     // local solar time ≥ 12 h
  double aoi_over_60_wh = 0.0;   // beam angle of incidence ≥ 60°
  double diffuse_rows_wh = 0.0;  // rows with beam < half of the plane's light
  double obstacle_day_wh = 0.0;  // UTC days the other-form obstacle stands on
  double p_el_wh = 0.0;          // the electrical part of total_wh
  double output_wh = 0.0;        // the null case's P_el + Q_th, for scale
};

Footprint Measure(const Plant& plant, const SelftestCase& effect, const SelftestCase& null_case,
                  std::uint64_t seed) {
  SelftestOptions options;
  std::vector<std::int64_t> days;
  SimOutputs with{}, without{};
  const Series data = SelftestData(plant, effect, seed, options, &days, &with);
  SelftestData(plant, null_case, seed, options, &days, &without);
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  const double dt_h = options.step_s / 3600.0;
  Footprint f;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const double d_el = without.p_el_w[i] - with.p_el_w[i];
    const double d_th = without.q_th_w[i] - with.q_th_w[i];
    if (!std::isfinite(d_el) || !std::isfinite(d_th)) continue;
    const double wh = (d_el + d_th) * dt_h;
    const double g = data[Channel::kGPoaWM2][i];
    const double diffuse = data[Channel::kGPoaDiffuseWM2][i];
    const double aoi_deg = RadToDeg(data[Channel::kAoiRad][i]);
    const double solar_h =
        static_cast<double>(data.time_s[i] - SolarDayStartS(data.time_s[i], offset_s)) / 3600.0;
    f.total_wh += wh;
    f.p_el_wh += d_el * dt_h;
    f.output_wh += (without.p_el_w[i] + without.q_th_w[i]) * dt_h;
    if (solar_h >= 12.0) f.afternoon_wh += wh;
    if (aoi_deg >= 60.0) f.aoi_over_60_wh += wh;
    if (!(g - diffuse >= 0.5 * g)) f.diffuse_rows_wh += wh;
    if (ObstacleOnDay(seed, data.time_s[i] / kSecondsPerDay)) f.obstacle_day_wh += wh;
  }
  return f;
}

std::vector<std::uint64_t> DevelopmentSeeds() {
  return testing::SeedsFromEnv("PVTWIN_OCTOBER_SEEDS", "1,2,3");
}

void Print(const char* name, std::uint64_t seed, const Footprint& f) {
  std::printf(
      "%-22s seed %3llu  footprint %7.1f Wh (%.2f %% of output; P_el %.0f %%)  afternoon %3.0f %%  "
      "AOI>=60 %3.0f %%  diffuse rows %3.0f %%  obstacle days %3.0f %%\n",
      name, static_cast<unsigned long long>(seed), f.total_wh, 100.0 * f.total_wh / f.output_wh,
      100.0 * f.p_el_wh / f.total_wh, 100.0 * f.afternoon_wh / f.total_wh,
      100.0 * f.aoi_over_60_wh / f.total_wh, 100.0 * f.diffuse_rows_wh / f.total_wh,
      100.0 * f.obstacle_day_wh / f.total_wh);
}

// What separates the obstacle from the IAM at low sun, and why the box
// candidate finds less of the obstacle in October: the IAM's footprint is
// balanced between morning and afternoon in both seasons; the obstacle's is
// an afternoon one in June, but in October, with the sun behind it only at
// AOI ≥ 60° late in the day, a larger share is the sky diffuse it hides
// all day on its days (f_d = 4.7 %, HorizonDiffuseShare), which the box
// (beam only) does not model. Printed per seed for doc/validation.md
// (PVTWIN_OCTOBER_SEEDS=1,2,3,101,102,103).
TEST(OctoberSeparation, ObstacleIsOneSidedInJuneAndLargelyDiffuseInOctoberTheIamBalanced) {
  const Plant plant = DesignExamplePlant();
  const std::vector<SelftestCase> cases = OtherFormSelftestCases(plant);
  for (std::uint64_t seed : DevelopmentSeeds()) {
    Footprint shading_by_season[2];
    for (int k = 0; k < 2; ++k) {
      const std::string season = k == 0 ? "" : "_october";
      const SelftestCase& null_case = CaseNamed(cases, "null" + season);
      const Footprint shading =
          Measure(plant, CaseNamed(cases, "shading" + season), null_case, seed);
      const Footprint iam = Measure(plant, CaseNamed(cases, "iam" + season), null_case, seed);
      const Footprint sky =
          Measure(plant, CaseNamed(cases, "sky_radiation" + season), null_case, seed);
      Print(("shading" + season).c_str(), seed, shading);
      Print(("iam" + season).c_str(), seed, iam);
      Print(("sky_radiation" + season).c_str(), seed, sky);
      // The obstacle acts on its days only (the collector's heat capacity
      // carries a little past midnight).
      EXPECT_NEAR(shading.obstacle_day_wh, shading.total_wh, 0.02 * std::fabs(shading.total_wh));
      // A symmetric IAM on a south-facing plane: as much before noon as after.
      EXPECT_NEAR(iam.afternoon_wh / iam.total_wh, 0.5, 0.1) << "seed " << seed << season;
      shading_by_season[k] = shading;
    }
    const Footprint& june = shading_by_season[0];
    const Footprint& october = shading_by_season[1];
    EXPECT_GT(june.afternoon_wh / june.total_wh, 0.8) << "seed " << seed;
    EXPECT_LT(october.afternoon_wh / october.total_wh, june.afternoon_wh / june.total_wh)
        << "seed " << seed;
    EXPECT_GT(october.diffuse_rows_wh / october.total_wh, june.diffuse_rows_wh / june.total_wh)
        << "seed " << seed;
  }
}

}  // namespace
}  // namespace pvtwin
