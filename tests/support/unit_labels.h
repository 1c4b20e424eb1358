// Checks that printed powers follow the one convention of io/platform/quantity_text.h:
// "71.70 W (39.83 W/m²)", the collector's figure first and the per-m² figure
// of the same quantity beside it.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>

namespace pvtwin::testing {

// Every "X W (Y W/m²)" pair in text satisfies X = Y · area_m2 (to the printed
// rounding), no MAE is printed in W/m² alone, and there are at least
// min_pairs pairs. Returns the number of pairs.
inline int ExpectPowersInWattsAndPerM2(const std::string& text, double area_m2, int min_pairs) {
  static const std::regex kPair(R"(([0-9]+\.[0-9]+) W \(([0-9]+\.[0-9]+) W/m²\))");
  int pairs = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kPair);
       it != std::sregex_iterator(); ++it, ++pairs) {
    const double w = std::stod((*it)[1].str());
    const double w_m2 = std::stod((*it)[2].str());
    // Both are rounded to 0.01: |w − w_m2·A| ≤ 0.005 + 0.005·A.
    EXPECT_NEAR(w, w_m2 * area_m2, 0.005 + 0.005 * area_m2 + 1e-9) << it->str() << "\n" << text;
  }
  // A label then directly a figure in W/m²: "MAE P_el 0.78 W/m²".
  static const std::regex kPerM2Only(R"(MAE[A-Za-z_ +()]*[0-9.]+ W/m(2|²))");
  std::smatch bare;
  EXPECT_FALSE(std::regex_search(text, bare, kPerM2Only))
      << "an MAE in W/m² alone: " << bare.str() << "\n"
      << text;
  EXPECT_GE(pairs, min_pairs) << text;
  return pairs;
}

}  // namespace pvtwin::testing
