#include "io/platform/quantity_text.h"

#include <cmath>
#include <cstdio>

namespace pvtwin {

std::string WattsAndPerM2(double w, double area_m2) {
  if (!std::isfinite(w)) return "n/a";
  char buf[80];
  if (area_m2 > 0.0) {
    std::snprintf(buf, sizeof buf, "%.2f W (%.2f W/m²)", w, w / area_m2);
  } else {
    std::snprintf(buf, sizeof buf, "%.2f W", w);
  }
  return buf;
}

}  // namespace pvtwin
