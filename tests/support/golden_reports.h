// What the golden folders under tests/golden record: for a config case the
// lines `pvtwin check-config` prints, for a CSV case the reader's errors,
// warnings and the series read. The tests compare these with expected.txt;
// the separate program pvtwin_golden_record (tests/golden_record.cc) writes
// them after an intended change, never the test run itself.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "config/plant_config.h"
#include "io/files/csv.h"
#include "tests/support/files.h"

namespace pvtwin::testing {

inline const std::filesystem::path kGoldenConfigDir =
    std::filesystem::path(PVTWIN_GOLDEN_DIR) / "config";
inline const std::filesystem::path kGoldenCsvDir = std::filesystem::path(PVTWIN_GOLDEN_DIR) / "csv";

// Every diagnostic of <case>/config.toml, one per line; *ok: it loaded.
inline std::string ConfigCaseReport(const std::filesystem::path& case_dir, bool* ok) {
  Config config;
  Diagnostics errors;
  *ok = ParseConfig(ReadFile(case_dir / "config.toml"), "config.toml", &config, &errors);
  std::string report;
  for (const Diagnostic& d : errors) report += d.ToString() + "\n";
  return report;
}

// How CsvCaseReport reads the case: as a stream (ParseCanonicalCsv), or as
// a file by ReadCanonicalCsv with every file large enough for its reading on
// two threads.
enum class CsvRead { kStream, kFileOnTwoThreads };

// <case>/input.csv read with fluid density 1040 kg/m³ and the example
// plant's area of 1.8 m² (for the area-scaled physical limits):
//   error: <diagnostic>      every error, in order
//   warning: <diagnostic>    every warning, in order
// and, if the file was read, "step_s = <median step>" followed by the series
// as WriteCsv writes it (time and every channel present, in channel order).
// Diagnostics name the file input.csv either way.
inline std::string CsvCaseReport(const std::filesystem::path& case_dir, bool* ok,
                                 CsvRead how = CsvRead::kStream) {
  Series series;
  Diagnostics errors;
  Diagnostics warnings;
  CsvReadOptions options;
  options.area_m2 = 1.8;
  if (how == CsvRead::kStream) {
    std::ifstream in(case_dir / "input.csv", std::ios::binary);
    *ok = ParseCanonicalCsv(in, "input.csv", options, &series, &errors, &warnings);
  } else {
    options.two_thread_bytes = 1;
    *ok = ReadCanonicalCsv((case_dir / "input.csv").string(), options, &series, &errors, &warnings);
    for (Diagnostics* list : {&errors, &warnings}) {
      for (Diagnostic& d : *list) d.file = "input.csv";
    }
  }
  std::ostringstream out;
  for (const Diagnostic& d : errors) out << "error: " << d.ToString() << "\n";
  for (const Diagnostic& d : warnings) out << "warning: " << d.ToString() << "\n";
  if (*ok) {
    std::vector<Channel> present;
    for (const ChannelInfo& info : kChannels) {
      if (series.Has(info.channel)) present.push_back(info.channel);
    }
    out << "step_s = " << series.step_s << "\n";
    WriteCsv(out, series, present);
  }
  return out.str();
}

}  // namespace pvtwin::testing
