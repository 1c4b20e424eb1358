// libFuzzer harness for the canonical CSV reader (io/files/csv.h), which reads
// whatever a user or a logger export hands to import, calibrate, simulate,
// backtest and diagnose. It must never crash, and what it accepts must hold
// the reader's promises: strictly increasing times, one value per row in
// every present channel, every value finite or missing and within its
// channel's physical limits (core/data/physical_limits.h), every diagnostic
// printable (no control bytes, cut cells). The same bytes read as a file on
// two threads (ReadCanonicalCsv, made to split any file) must give the same
// result and diagnostics as the stream. Seeds: tests/fuzz/corpus/csv/.
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/data/physical_limits.h"
#include "io/files/csv.h"

namespace {

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

// The input as a file: a memory file, rewritten for each input, opened by
// its /proc/self/fd path.
std::string AsFile(const std::uint8_t* data, std::size_t size) {
  static const int fd = memfd_create("fuzz.csv", 0);
  Require(fd >= 0 && ftruncate(fd, 0) == 0);
  Require(size == 0 || pwrite(fd, data, size, 0) == static_cast<ssize_t>(size));
  return "/proc/self/fd/" + std::to_string(fd);
}

bool SameValues(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  }
  return true;
}

bool SameDiagnostics(const pvtwin::Diagnostics& a, const pvtwin::Diagnostics& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].ToString() != b[i].ToString()) return false;
  }
  return true;
}

void RequirePrintable(const pvtwin::Diagnostic& d) {
  const std::string text = d.ToString();
  // A cell is cut to kMaxExcerptBytes (escaped, up to 4 bytes per byte).
  Require(text.size() < d.file.size() + d.rule.size() + 2 * (4 * pvtwin::kMaxExcerptBytes + 40));
  for (const char c : text) Require(static_cast<unsigned char>(c) >= 0x20 || c == '\t');
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = AsFile(data, size);
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  pvtwin::CsvReadOptions options;
  options.area_m2 = 1.8;
  pvtwin::Series series;
  pvtwin::Diagnostics errors, warnings;
  const bool ok = pvtwin::ParseCanonicalCsv(in, path, options, &series, &errors, &warnings);
  for (const pvtwin::Diagnostic& d : errors) RequirePrintable(d);
  for (const pvtwin::Diagnostic& d : warnings) RequirePrintable(d);
  Require(ok == errors.empty());

  options.two_thread_bytes = 1;
  pvtwin::Series split;
  pvtwin::Diagnostics split_errors, split_warnings;
  Require(pvtwin::ReadCanonicalCsv(path, options, &split, &split_errors, &split_warnings) == ok);
  Require(SameDiagnostics(split_errors, errors) && SameDiagnostics(split_warnings, warnings));
  if (!ok) return 0;
  Require(split.time_s == series.time_s && split.step_s == series.step_s);
  for (std::size_t c = 0; c < pvtwin::kNumChannels; ++c) {
    Require(SameValues(split.columns[c], series.columns[c]));
  }
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
