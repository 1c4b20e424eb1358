#include "core/diagnostic.h"

namespace pvtwin {

std::string Diagnostic::ToString() const {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line);
  if (!out.empty()) out += ": ";
  if (!field.empty()) {
    out += field;
    if (!value.empty()) out += " = " + value;
    out += ": ";
  }
  out += rule;
  return out;
}

}  // namespace pvtwin
