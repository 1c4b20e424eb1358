// libFuzzer harness for the canonical CSV reader (io/csv.h), which reads
// whatever a user or a logger export hands to import, calibrate, simulate,
// backtest and diagnose. It must never crash, and what it accepts must hold
// the reader's promises: strictly increasing times, one value per row in
// every present channel, every value finite or missing and within its
// channel's physical limits (core/data/physical_limits.h), every diagnostic
// printable (no control bytes, cut cells). Seeds: tests/fuzz/corpus/csv/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "core/data/physical_limits.h"
#include "io/csv.h"

namespace {

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

void RequirePrintable(const pvtwin::Diagnostic& d) {
  const std::string text = d.ToString();
  // A cell is cut to kMaxExcerptBytes (escaped, up to 4 bytes per byte).
  Require(text.size() < d.file.size() + d.rule.size() + 2 * (4 * pvtwin::kMaxExcerptBytes + 40));
  for (const char c : text) Require(static_cast<unsigned char>(c) >= 0x20 || c == '\t');
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  pvtwin::CsvReadOptions options;
  options.area_m2 = 1.8;
  pvtwin::Series series;
  pvtwin::Diagnostics errors, warnings;
  const bool ok = pvtwin::ParseCanonicalCsv(in, "fuzz.csv", options, &series, &errors, &warnings);
  for (const pvtwin::Diagnostic& d : errors) RequirePrintable(d);
  for (const pvtwin::Diagnostic& d : warnings) RequirePrintable(d);
  Require(ok == errors.empty());
  if (!ok) return 0;
  for (std::size_t i = 1; i < series.size(); ++i) Require(series.time_s[i] > series.time_s[i - 1]);
  for (std::size_t c = 0; c < pvtwin::kNumChannels; ++c) {
    const auto channel = static_cast<pvtwin::Channel>(c);
    if (!series.Has(channel)) continue;
    Require(series.columns[c].size() == series.size());
    const pvtwin::PhysicalLimit limit = pvtwin::PhysicalLimitOf(channel, options.area_m2);
    for (const double x : series.columns[c]) Require(std::isnan(x) || limit.Contains(x));
  }
  return 0;
}
