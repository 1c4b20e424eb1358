// The diagnosis names a sensor fault that is plausible on every row: the
// inlet temperature reading high by a constant from one day on (the heat
// meter then reads ṁ·c_p·ΔT low), with its channel, onset and size, and
// names none on the same plant without it.
#include <gtest/gtest.h>

#include <string>

#include "core/common/calendar.h"
#include "core/data/qc.h"
#include "core/diagnosis/diagnosis.h"
#include "core/synth/synthetic_plant.h"
#include "tests/support/synthetic_series.h"

namespace pvtwin {
namespace {

Series Plant21Days(const Plant& plant, double offset_k, std::int64_t* onset_s) {
  SyntheticOptions synth;
  std::string error;
  EXPECT_TRUE(DefaultSyntheticOptions(plant, "1N1Cwr", 21, 3, &synth, &error)) << error;
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  const std::int64_t first = SolarDayStartS(synth.weather.start_time_s, offset_s) + kSecondsPerDay;
  synth.weather.start_time_s = first;
  *onset_s = first + 16 * kSecondsPerDay;  // the third held-out day
  if (offset_k != 0.0) {
    synth.disturbances.push_back(
        {DisturbanceKind::kInletSensorOffset, *onset_s, first + 30 * kSecondsPerDay, offset_k});
  }
  Series s = MakeSyntheticPlantData(plant, synth);
  ApplyPaperCorrections(&s);
  return s;
}

DiagnosisResult DiagnoseSoilingOnly(const Series& s, const Plant& plant) {
  DiagnosisOptions o;
  o.train_days = 14;
  o.heldout_days = 7;
  o.effects = {"soiling"};  // the sensor test does not depend on the candidates
  DiagnosisResult r;
  std::string error;
  EXPECT_TRUE(Diagnose(s, plant, testing::SpecOf("1N1Cwr"), o, &r, &error)) << error;
  return r;
}

TEST(DiagnosisSensors, InletOffsetFromOneDayOnIsNamedWithChannelOnsetAndSize) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  const DiagnosisResult r = DiagnoseSoilingOnly(Plant21Days(plant, 1.5, &onset_s), plant);
  const SensorFinding* step = nullptr;
  for (const SensorFinding& f : r.sensors) {
    if (f.kind == "offset_step") step = &f;
  }
  ASSERT_NE(step, nullptr) << r.verdict_sentence;
  EXPECT_EQ(step->channel, "t_in_c");
  EXPECT_EQ(step->from, SolarDate(onset_s, SolarDayOffsetS(plant)));
  EXPECT_GT(step->size, 0.75);  // the model's own response to the high inlet absorbs a part
  EXPECT_LT(step->size, 1.8);
  EXPECT_NE(r.verdict_sentence.find("t_in_c offset_step from"), std::string::npos);
}

TEST(DiagnosisSensors, NoOffsetStepOnTheSamePlantWithoutIt) {
  const Plant plant = DesignExamplePlant();
  std::int64_t onset_s = 0;
  const DiagnosisResult r = DiagnoseSoilingOnly(Plant21Days(plant, 0.0, &onset_s), plant);
  for (const SensorFinding& f : r.sensors) EXPECT_NE(f.kind, "offset_step") << f.detail;
}

}  // namespace
}  // namespace pvtwin
