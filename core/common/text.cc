#include "core/common/text.h"

#include <sstream>

namespace pvtwin {

std::string FixedDecimals(double x, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << x;
  return s.str();
}

}  // namespace pvtwin
