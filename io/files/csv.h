// The canonical CSV of doc/contracts.md: reader and writer.
//
// Reading: a header row, comma separated, '.' decimal, column order free.
//   * `time`: ISO 8601 with Z or an offset, or unix seconds, decided per cell
//     (io/platform/time_format.h); it marks the start of the row's interval.
//     Rows must be strictly increasing in time, each within
//     1980-01-01T00:00:00Z .. 2200-01-01T00:00:00Z (a time before is a clock
//     at its zero or a relative time, e.g. -5, not a measurement).
//   * Every other known column goes to its Channel (core/channels.h); rh_pct
//     and p_air_hpa go to Series' air channels (AirChannel), unchecked.
//     `flow_l_h` becomes kMdotKgS: kg/s = L/h · ρ / 3.6e6, with ρ from
//     CsvReadOptions; `aoi_deg` becomes kAoiRad in radians. `valid` is 0 or 1.
//   * Empty cells and "nan" (any case) are missing values (NaN).
//   * Required: time; t_in_c and t_out_c (or q_th_w); flow_kg_s or flow_l_h;
//     g_poa_w_m2 or ghi_w_m2 + dhi_w_m2; t_amb_c; p_el_w. Each missing one is
//     an error naming the column.
//   * Unknown columns: one warning each, ignored. Duplicate columns (also
//     flow_kg_s together with flow_l_h): error.
//   * The paper's corrections (core/qc.h) are applied after reading:
//     short-wave irradiance > 5000 W/m² → 0, and negative flows down to
//     -1e-3 kg/s → 0 (one warning per kind with the count). A flow below that
//     is an error naming the line.
//   * Series::step_s is the median spacing of the rows (0 for fewer than 2).
// Errors carry file, line (1 = header), column, value and rule. After
// kMaxCsvErrors errors reading stops, with one more error saying so.
//
// Writing: `time` as ISO 8601 UTC with Z, then the requested channels in the
// given order, numbers in the shortest form that reads back exactly, missing
// values as empty cells. kMdotKgS is written as flow_kg_s, kAoiRad as aoi_deg.
#pragma once

#include <iosfwd>
#include <span>
#include <string>

#include "core/common/channels.h"
#include "core/common/diagnostic.h"
#include "core/common/series.h"

namespace pvtwin {

class NaiveTimeZone;

inline constexpr std::size_t kMaxCsvErrors = 100;

// ReadCanonicalCsv reads a file with this many bytes of rows or more on two
// threads, each half of the rows; the result and the diagnostics are those
// of a reading in one piece (CsvReadOptions::two_thread_bytes).
inline constexpr std::size_t kCsvTwoThreadBytes = std::size_t{1} << 20;

struct CsvReadOptions {
  double fluid_density_kg_m3 = 1040;  // converts flow_l_h to kg/s (plant config)
  // Collector area for the area-scaled physical limits (flow, P_el, Q_u);
  // 0: unknown, the widest limits (core/physical_limits.h).
  double area_m2 = 0.0;
  // Zone of `time` cells without Z or offset (io/platform/local_time.h); null: such
  // cells are an error, a local time says nothing about its instant.
  const NaiveTimeZone* naive_time_zone = nullptr;
  // A weather file (pvtwin import-weather): required are only `time`,
  // g_poa_w_m2 or ghi_w_m2 + dhi_w_m2, and t_amb_c.
  bool weather_only = false;
  // ReadCanonicalCsv reads a file with at least this many bytes after the
  // header on two threads (the tests and the fuzzer set it low, so that
  // small files take that path too).
  std::size_t two_thread_bytes = kCsvTwoThreadBytes;
};

// The physical limits of channel c (core/data/physical_limits.h) as "[lo,
// hi] unit" in the unit of its CSV column (aoi_deg in degrees: core holds
// radians, the CSV edge converts).
std::string DescribeCsvLimit(Channel c, double area_m2);

// Reads the file at path. Returns true if it was read without errors; then
// *out holds the series (it is not written otherwise). Errors go to *errors
// (not null); warnings go to *warnings (may be null to discard them).
bool ReadCanonicalCsv(const std::string& path, const CsvReadOptions& options, Series* out,
                      Diagnostics* errors, Diagnostics* warnings);

// As ReadCanonicalCsv, from a stream; diagnostics name path_for_messages.
bool ParseCanonicalCsv(std::istream& in, const std::string& path_for_messages,
                       const CsvReadOptions& options, Series* out, Diagnostics* errors,
                       Diagnostics* warnings);

// Writes time and the given channels, in that order. A channel the series
// does not have is written as an empty column. Returns false and sets *error
// if the file cannot be written.
bool WriteCsv(const std::string& path, const Series& series, std::span<const Channel> channels,
              std::string* error);

// As WriteCsv, to a stream (the caller checks the stream's state).
void WriteCsv(std::ostream& out, const Series& series, std::span<const Channel> channels);

}  // namespace pvtwin
