#include "core/common/text.h"

#include <cstdio>
#include <sstream>

namespace pvtwin {

std::string FixedDecimals(double x, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << x;
  return s.str();
}

std::string SignificantDigits(double x, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

}  // namespace pvtwin
