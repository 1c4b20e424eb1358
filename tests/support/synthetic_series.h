// Small hand-made input series for model tests: every row gets the same
// inputs unless a test overrides a column.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/series.h"
#include "core/model/variant.h"
#include "tests/support/fixtures.h"

namespace pvtwin::testing {

struct ConstantInputs {
  double t_in_c = 20.0;
  double mdot_kg_s = 0.03;
  double g_poa_w_m2 = 0.0;
  double t_amb_c = 10.0;
  double wind_m_s = 2.0;
  double t_sky_c = -5.0;
  double t_back_c = 10.0;
};

inline Series MakeConstantSeries(std::size_t rows, double step_s, const ConstantInputs& in,
                                 std::int64_t t0_s = 1'600'000'000) {
  Series s;
  s.step_s = step_s;
  s.time_s.resize(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    s.time_s[i] = t0_s + static_cast<std::int64_t>(static_cast<double>(i) * step_s);
  }
  auto fill = [&s, rows](Channel c, double v) { s[c].assign(rows, v); };
  fill(Channel::kTInC, in.t_in_c);
  fill(Channel::kMdotKgS, in.mdot_kg_s);
  fill(Channel::kGPoaWM2, in.g_poa_w_m2);
  fill(Channel::kTAmbC, in.t_amb_c);
  fill(Channel::kWindMS, in.wind_m_s);
  fill(Channel::kTSkyC, in.t_sky_c);
  fill(Channel::kTBackC, in.t_back_c);
  fill(Channel::kValid, 1.0);
  return s;
}

// Adds the in-plane diffuse irradiance that the 'I' variants need to split
// g_poa_w_m2 into beam and diffuse parts (core/physics/irradiance.h,
// SplitMeasuredPoa): `fraction` of g_poa_w_m2 on every row.
inline void AddPoaDiffuse(Series* s, double fraction) {
  const std::vector<double>& g_poa = (*s)[Channel::kGPoaWM2];
  std::vector<double> diffuse(g_poa.size());
  for (std::size_t i = 0; i < g_poa.size(); ++i) diffuse[i] = fraction * g_poa[i];
  (*s)[Channel::kGPoaDiffuseWM2] = diffuse;
}

// The parsed variant; a bad name fails the calling test.
inline ModelSpec SpecOf(const std::string& name) {
  ModelSpec spec;
  std::string error;
  EXPECT_TRUE(ParseVariant(name, &spec, &error)) << name << ": " << error;
  return spec;
}

}  // namespace pvtwin::testing
