#include "core/common/diagnostic.h"

#include <cstdio>

namespace pvtwin {

namespace {

// Length of the valid UTF-8 sequence at s[i], 0 if there is none.
std::size_t Utf8Length(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(i);
  std::size_t n = b < 0x80           ? 1
                  : (b >> 5) == 0x6  ? 2
                  : (b >> 4) == 0xE  ? 3
                  : (b >> 3) == 0x1E ? 4
                                     : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  }
  return n;
}

}  // namespace

std::string PrintableExcerpt(const std::string& text) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size() && out.size() < kMaxExcerptBytes) {
    const std::size_t n = Utf8Length(text, i);
    const auto b = static_cast<unsigned char>(text[i]);
    if (n == 0 || (n == 1 && (b < 0x20 || b == 0x7F))) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", b);
      out += hex;
      ++i;
    } else {
      out.append(text, i, n);
      i += n;
    }
  }
  if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string Diagnostic::ToString() const {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line);
  if (!out.empty()) out += ": ";
  if (!field.empty()) {
    out += PrintableExcerpt(field);
    if (!value.empty()) out += " = " + PrintableExcerpt(value);
    out += ": ";
  }
  out += rule;
  return out;
}

}  // namespace pvtwin
