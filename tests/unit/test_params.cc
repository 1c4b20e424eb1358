#include <gtest/gtest.h>

#include "core/common/params.h"

namespace pvtwin {
namespace {

TEST(ParamTable, EntriesAreInEnumOrderWithOrderedBounds) {
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const ParamInfo& info = kParamTable[i];
    EXPECT_EQ(static_cast<std::size_t>(info.param), i) << info.name;
    EXPECT_LE(info.lower, info.start) << info.name;
    EXPECT_LE(info.start, info.upper) << info.name;
    if (info.scale == ParamScale::kLog) {
      EXPECT_GT(info.lower, 0.0) << info.name;
    }
    EXPECT_EQ(ParamFromName(info.name), info.param);
  }
}

TEST(ParamTable, PlantRelativeEntriesResolveToAbsoluteValues) {
  Plant plant;
  plant.area_m2 = 2.0;
  plant.pv_temp_coeff_per_k = -0.004;
  const ParamInfo area = ResolvedInfo(Param::kAreaM2, plant);
  EXPECT_DOUBLE_EQ(area.start, 2.0);
  EXPECT_DOUBLE_EQ(area.lower, 1.0);
  EXPECT_DOUBLE_EQ(area.upper, 3.0);
  const ParamInfo temp = ResolvedInfo(Param::kPvTempCoeffPerK, plant);
  EXPECT_DOUBLE_EQ(temp.start, -0.004);
  EXPECT_DOUBLE_EQ(temp.lower, -0.006);  // interval flipped for a negative reference
  EXPECT_DOUBLE_EQ(temp.upper, -0.002);
}

}  // namespace
}  // namespace pvtwin
