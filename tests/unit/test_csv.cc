// Canonical CSV: time text, round trip through WriteCsv and the reader, and
// the real htw saar test-bench days (tests/data/htwsaar-pvt, PROVENANCE.md).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "io/files/csv.h"
#include "io/platform/local_time.h"
#include "io/platform/time_format.h"
#include "tests/support/fixtures.h"

namespace pvtwin {
namespace {

// 2024-06-01T00:00:00Z: rows of the tests below start here, a plausible
// measurement time (the reader refuses times before 1980).
using testing::kJune1_2024UtcS;
std::string RowTime(std::int64_t offset_s) { return std::to_string(kJune1_2024UtcS + offset_s); }

const std::string kRealDataDir = std::string(PVTWIN_DATA_DIR) + "/htwsaar-pvt/";

std::int64_t Parsed(std::string_view text) {
  std::int64_t unix_s = -1;
  std::string error;
  EXPECT_TRUE(ParseTime(text, &unix_s, &error)) << text << ": " << error;
  return unix_s;
}

std::string ParseError(std::string_view text) {
  std::int64_t unix_s = 12345;
  std::string error;
  EXPECT_FALSE(ParseTime(text, &unix_s, &error)) << text;
  EXPECT_EQ(unix_s, 12345) << "output written on failure";
  return error;
}

TEST(CsvTimeFormat, ParsesIsoUtcOffsetsAndUnixSeconds) {
  // 2017-08-07T08:24:01Z, checked with `date -u -d 2017-08-07T08:24:01Z +%s`.
  constexpr std::int64_t kT = 1502094241;
  EXPECT_EQ(Parsed("2017-08-07T08:24:01Z"), kT);
  EXPECT_EQ(Parsed("2017-08-07T10:24:01+02:00"), kT);
  EXPECT_EQ(Parsed("2017-08-07T03:54:01-04:30"), kT);
  EXPECT_EQ(Parsed("2017-08-07T10:24:01+0200"), kT);
  EXPECT_EQ(Parsed("2017-08-07T10:24:01+02"), kT);
  EXPECT_EQ(Parsed("2017-08-07 08:24:01z"), kT);
  EXPECT_EQ(Parsed("2017-08-07T08:24:01.999Z"), kT);  // fractions floor
  EXPECT_EQ(Parsed("2017-08-07T08:24:01,5Z"), kT);
  EXPECT_EQ(Parsed("2017-08-07T08:24Z"), kT - 1);
  EXPECT_EQ(Parsed("1502094241"), kT);
  EXPECT_EQ(Parsed("1502094241.75"), kT);
  EXPECT_EQ(Parsed("+1502094241"), kT);
  EXPECT_EQ(Parsed("0"), 0);
  EXPECT_EQ(Parsed("-1.5"), -2);
  EXPECT_EQ(Parsed("1970-01-01T00:00:00Z"), 0);
  EXPECT_EQ(Parsed("1969-12-31T23:59:59Z"), -1);
  EXPECT_EQ(Parsed("2016-02-29T00:00:00Z"), 1456704000);
  EXPECT_EQ(Parsed("2000-03-01T00:00:00+00:00"), 951868800);
}

TEST(CsvTimeFormat, RejectsAmbiguousOrMalformedTimes) {
  EXPECT_EQ(ParseError("2017-08-07T08:24:01"),
            "time needs Z or a ±HH:MM offset (local time is ambiguous; --timezone says which zone "
            "naive times are in)");
  EXPECT_EQ(ParseError("2017-02-29T00:00:00Z"), "no such date");
  EXPECT_EQ(ParseError("2017-13-01T00:00:00Z"), "no such date");
  EXPECT_EQ(ParseError("2017-08-07T24:00:00Z"), "time of day out of range");
  EXPECT_EQ(ParseError("2017-08-07T08:24:60Z"), "time of day out of range");
  EXPECT_EQ(ParseError("2017-08-07T08:24:00+25:00"), "UTC offset out of range");
  EXPECT_EQ(ParseError(""), "must not be empty");
  for (const char* bad : {"2017-08-07", "2017-8-7T08:24:00Z", "2017-08-07T08:24:00ZZ",
                          "2017-08-07T08:24:00.Z", "1.5e9", "12:00", "-", "1502094241x"}) {
    EXPECT_FALSE(ParseError(bad).empty()) << bad;
  }
}

// Naive times in a zone: Vienna is UTC+2 in July and UTC+1 in January; a
// fixed offset ignores the season; a time with Z keeps its own instant.
TEST(CsvTimeFormat, NaiveTimesTakeTheZoneOfTheirSeason) {
  std::string error;
  const std::optional<NaiveTimeZone> vienna = NaiveTimeZone::Parse("Europe/Vienna", &error);
  ASSERT_TRUE(vienna) << error;
  const std::optional<NaiveTimeZone> plus_one = NaiveTimeZone::Parse("UTC+01:00", &error);
  ASSERT_TRUE(plus_one) << error;
  auto utc = [](const char* text) {
    std::int64_t t = 0;
    std::string e;
    EXPECT_TRUE(ParseTime(text, &t, &e)) << e;
    return t;
  };
  std::int64_t t = 0;
  ASSERT_TRUE(ParseTimeIn("2024-07-01 12:00", &*vienna, 0, &t, &error)) << error;
  EXPECT_EQ(t, utc("2024-07-01T10:00:00Z"));
  ASSERT_TRUE(ParseTimeIn("2024-01-15T12:00:30", &*vienna, 0, &t, &error)) << error;
  EXPECT_EQ(t, utc("2024-01-15T11:00:30Z"));
  ASSERT_TRUE(ParseTimeIn("2024-07-01 12:00", &*plus_one, 0, &t, &error)) << error;
  EXPECT_EQ(t, utc("2024-07-01T11:00:00Z"));
  ASSERT_TRUE(ParseTimeIn("2024-07-01T12:00:00Z", &*vienna, 0, &t, &error)) << error;
  EXPECT_EQ(t, utc("2024-07-01T12:00:00Z"));
  // 02:30 on 2024-10-27 happens twice: first at 00:30 UTC, then at 01:30 UTC.
  ASSERT_TRUE(ParseTimeIn("2024-10-27 02:30", &*vienna, 0, &t, &error)) << error;
  EXPECT_EQ(t, utc("2024-10-27T00:30:00Z"));
  ASSERT_TRUE(ParseTimeIn("2024-10-27 02:30", &*vienna, utc("2024-10-27T00:45:00Z"), &t, &error));
  EXPECT_EQ(t, utc("2024-10-27T01:30:00Z"));
  EXPECT_FALSE(ParseTimeIn("2024-03-31 02:30", &*vienna, 0, &t, &error));
  EXPECT_FALSE(NaiveTimeZone::Parse("+15:00", &error));
  EXPECT_FALSE(NaiveTimeZone::Parse("Europe/Atlantis", &error));
}

TEST(CsvTimeFormat, CommandLineTimesTakeDatesNowAndRelativeTimes) {
  const std::int64_t now_s = 1795400000;  // 2026-11-23T03:33:20Z
  std::int64_t t = 0;
  std::string error;
  // `date -u -d 2026-11-22 +%s`
  ASSERT_TRUE(ParseTimeArgument("2026-11-22", now_s, &t, &error)) << error;
  EXPECT_EQ(t, 1795305600);
  ASSERT_TRUE(ParseTimeArgument("-14d", now_s, &t, &error)) << error;
  EXPECT_EQ(t, now_s - 14 * 86400);
  ASSERT_TRUE(ParseTimeArgument("-6h", now_s, &t, &error)) << error;
  EXPECT_EQ(t, now_s - 6 * 3600);
  ASSERT_TRUE(ParseTimeArgument("+30m", now_s, &t, &error)) << error;
  EXPECT_EQ(t, now_s + 1800);
  ASSERT_TRUE(ParseTimeArgument("now", now_s, &t, &error)) << error;
  EXPECT_EQ(t, now_s);
  ASSERT_TRUE(ParseTimeArgument("2026-11-22T06:00:00+02:00", now_s, &t, &error)) << error;
  EXPECT_EQ(t, 1795305600 + 4 * 3600);
  ASSERT_TRUE(ParseTimeArgument("-14", now_s, &t, &error)) << error;  // unix seconds
  EXPECT_EQ(t, -14);
  for (const char* bad : {"yesterday", "-14w", "-d", "2026-13-01", "-1.5d"}) {
    t = 12345;
    EXPECT_FALSE(ParseTimeArgument(bad, now_s, &t, &error)) << bad;
    EXPECT_NE(error.find("-14d"), std::string::npos) << bad << ": " << error;
    EXPECT_EQ(t, 12345) << bad;
  }
}

TEST(CsvTimeFormat, FormatsUtcWithZAndRoundTrips) {
  EXPECT_EQ(FormatIsoUtc(1502094241), "2017-08-07T08:24:01Z");
  EXPECT_EQ(FormatIsoUtc(0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(FormatIsoUtc(-1), "1969-12-31T23:59:59Z");
  EXPECT_EQ(FormatIsoUtc(1456704000), "2016-02-29T00:00:00Z");
  for (std::int64_t t = -100000000; t < 4000000000; t += 7777777) {
    EXPECT_EQ(Parsed(FormatIsoUtc(t)), t);
  }
}

Series MakeSeries() {
  Series s;
  s.step_s = 60;
  for (int i = 0; i < 5; ++i) s.time_s.push_back(1502094240 + 60 * i);
  for (const ChannelInfo& info : kChannels) {
    std::vector<double>& col = s.Ensure(info.channel);
    for (std::size_t i = 0; i < s.size(); ++i) {
      col[i] = 0.1 * static_cast<double>(i + 1) + 1.0 / 3.0 + static_cast<double>(info.channel);
    }
  }
  for (double& lw_w_m2 : s[Channel::kLwDownWM2]) lw_w_m2 += 300.0;  // within its physical limits
  s[Channel::kValid] = {1, 0, 1, 1, 0};
  s[Channel::kAoiRad] = {0.1, 0.2, 1.0 / 3.0, kPi / 4, 1.5};
  s[Channel::kMdotKgS][3] = 0.0;
  s[Channel::kTAmbC][2] = std::nan("");  // missing cell
  s[Channel::kPElW][4] = -1e-300;        // tiny and negative
  s[Channel::kQThW][1] = 123456789.123456789;
  return s;
}

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("pvtwin_test_" + std::to_string(getpid()) + "_" + name))
      .string();
}

TEST(CsvRoundTrip, WriteThenReadGivesTheSameSeries) {
  const Series written = MakeSeries();
  std::vector<Channel> all;
  for (const ChannelInfo& info : kChannels) all.push_back(info.channel);
  const std::string path = TempPath("roundtrip.csv");
  std::string error;
  ASSERT_TRUE(WriteCsv(path, written, all, &error)) << error;

  Series read;
  Diagnostics errors;
  Diagnostics warnings;
  ASSERT_TRUE(ReadCanonicalCsv(path, CsvReadOptions{}, &read, &errors, &warnings))
      << errors.front().ToString();
  std::filesystem::remove(path);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(read.time_s, written.time_s);
  EXPECT_EQ(read.step_s, 60);
  for (const ChannelInfo& info : kChannels) {
    ASSERT_TRUE(read.Has(info.channel)) << info.name;
    for (std::size_t i = 0; i < written.size(); ++i) {
      const double expected = written.At(info.channel, i);
      const double actual = read.At(info.channel, i);
      if (std::isnan(expected)) {
        EXPECT_TRUE(std::isnan(actual)) << info.name << " row " << i;
      } else if (info.channel == Channel::kAoiRad) {
        // Degrees in the file: one multiplication each way.
        EXPECT_NEAR(actual, expected, 4e-16 * expected) << "row " << i;
      } else {
        EXPECT_EQ(actual, expected) << info.name << " row " << i;  // exact
      }
    }
  }
}

TEST(CsvRoundTrip, WritesOnlyTheRequestedChannelsInOrder) {
  Series s = MakeSeries();
  s[Channel::kWindMS].clear();  // absent: written as an empty column
  const std::vector<Channel> channels = {Channel::kPElW, Channel::kWindMS, Channel::kAoiRad};
  std::ostringstream out;
  WriteCsv(out, s.Slice(0, 1), channels);
  EXPECT_EQ(out.str(),
            "time,p_el_w,wind_m_s,aoi_deg\n"
            "2017-08-07T08:24:00Z,14.433333333333334,,5.729577951308233\n");
}

TEST(CsvRoundTrip, UnwritablePathIsAnError) {
  std::string error;
  EXPECT_FALSE(WriteCsv("/nonexistent/dir/out.csv", MakeSeries(), {}, &error));
  EXPECT_NE(error.find("/nonexistent/dir/out.csv"), std::string::npos) << error;
}

bool ParseText(const std::string& text, Series* series, Diagnostics* errors,
               const CsvReadOptions& options = {}) {
  std::istringstream in(text);
  Diagnostics warnings;
  return ParseCanonicalCsv(in, "in.csv", options, series, errors, &warnings);
}

TEST(CsvRead, AcceptsCrlfByteOrderMarkSpacesAndEmptyLines) {
  const std::string text =
      "\xEF\xBB\xBFtime, t_in_c ,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\r\n"
      "1717200000,1,2,0.03,500, 20 ,+100\r\n"
      "\r\n"
      "1717200060,1,2,0.03,,20,nan\r\n";
  Series s;
  Diagnostics errors;
  ASSERT_TRUE(ParseText(text, &s, &errors)) << errors.front().ToString();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s.time_s[1], kJune1_2024UtcS + 60);
  EXPECT_EQ(s[Channel::kTInC][0], 1.0);
  EXPECT_EQ(s[Channel::kTAmbC][0], 20.0);
  EXPECT_EQ(s[Channel::kPElW][0], 100.0);
  EXPECT_TRUE(std::isnan(s[Channel::kGPoaWM2][1]));
  EXPECT_TRUE(std::isnan(s[Channel::kPElW][1]));
  EXPECT_FALSE(s.Has(Channel::kWindMS));
}

// A row without quotes is split by a fast path, one with a quote by the
// general one: the same cells, blanks around them, an empty one and one at
// the end read alike either way, and a quote inside a plain cell is that
// cell's text (which then is no number).
TEST(CsvRead, RowsWithAndWithoutQuotesReadAlike) {
  const std::string header = "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n";
  const std::string plain =
      RowTime(0) + ", 1.5 ,2,0.03,\t500\t,,100\n" + RowTime(60) + ",1,2,0.03,500,20,\n";
  const std::string quoted = "\"" + RowTime(0) +
                             "\", \"1.5\" ,\"2\",\"0.03\",\t\"500\"\t,\"\",\"100\"\n\"" +
                             RowTime(60) + "\",\"1\",\"2\",\"0.03\",\"500\",\"20\",\"\"\n";
  Series a, b;
  Diagnostics errors;
  ASSERT_TRUE(ParseText(header + plain, &a, &errors)) << errors.front().ToString();
  ASSERT_TRUE(ParseText(header + quoted, &b, &errors)) << errors.front().ToString();
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(a.time_s, b.time_s);
  for (const Channel c : {Channel::kTInC, Channel::kTOutC, Channel::kMdotKgS, Channel::kGPoaWM2,
                          Channel::kTAmbC, Channel::kPElW}) {
    for (std::size_t i = 0; i < 2; ++i) {
      const double x = a[c][i];
      const double y = b[c][i];
      EXPECT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << i << ": " << x << " " << y;
    }
  }
  EXPECT_EQ(a[Channel::kTInC][0], 1.5);
  EXPECT_EQ(a[Channel::kGPoaWM2][0], 500.0);
  EXPECT_TRUE(std::isnan(a[Channel::kTAmbC][0]));
  EXPECT_TRUE(std::isnan(a[Channel::kPElW][1]));
  Series c;
  errors.clear();
  EXPECT_FALSE(ParseText(header + RowTime(0) + ",1,2,0.03,5\"00,20,100\n", &c, &errors));
  ASSERT_FALSE(errors.empty());
  EXPECT_EQ(errors.front().field, "g_poa_w_m2");
  EXPECT_EQ(errors.front().value, "5\"00");
}

// A stream buffer over a string that cannot seek, as a pipe's.
class UnseekableBuf : public std::streambuf {
 public:
  explicit UnseekableBuf(std::string text) : text_(std::move(text)) {
    setg(text_.data(), text_.data(), text_.data() + text_.size());
  }

 private:
  std::string text_;
};

TEST(CsvRead, AStreamThatCannotSeekReadsAsAFileDoes) {
  // The reader reserves room for the rows from the bytes left after the
  // first row; a pipe tells no size, and rows longer than the first would
  // outgrow the estimate.
  std::string text =
      "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n" + RowTime(0) + ",1,2,0,0,9,0\n";
  for (int i = 1; i < 3000; ++i) {
    text += RowTime(60 * i) + ",21.125,22.5,0.0316,812.75,19.0625," + std::to_string(100 + i % 7) +
            ".5\n";
  }
  Series from_string;
  Diagnostics errors;
  ASSERT_TRUE(ParseText(text, &from_string, &errors)) << errors.front().ToString();
  UnseekableBuf buf(text);
  std::istream pipe(&buf);
  ASSERT_EQ(pipe.tellg(), std::istream::pos_type(-1));
  Series from_pipe;
  Diagnostics warnings;
  ASSERT_TRUE(ParseCanonicalCsv(pipe, "pipe.csv", {}, &from_pipe, &errors, &warnings))
      << errors.front().ToString();
  ASSERT_EQ(from_string.size(), 3000u);
  EXPECT_EQ(from_pipe.time_s, from_string.time_s);
  for (Channel c : {Channel::kTInC, Channel::kGPoaWM2, Channel::kPElW}) {
    EXPECT_EQ(from_pipe[c], from_string[c]);
  }
  EXPECT_EQ(from_string[Channel::kPElW][2999], 100 + 2999 % 7 + 0.5);
}

// A file of `rows` rows of 1-min data, written to `path`, with the text's
// awkward parts spread through it: CRLF on every third line, a blank line
// every 997 rows, and the cells of `bad` (row, column, text) put in.
struct BadCell {
  int row;
  int column;  // of time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w
  std::string text;
};
std::string LargeCsvText(int rows, const std::vector<BadCell>& bad) {
  std::string text = "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n";
  for (int i = 0; i < rows; ++i) {
    std::vector<std::string> cells = {std::to_string(1700000000 + 60 * i),
                                      "21.125",
                                      "22.5",
                                      "0.0316",
                                      "812.75",
                                      std::to_string(10 + i % 13) + ".0625",
                                      std::to_string(100 + i % 7) + ".5"};
    for (const BadCell& b : bad) {
      if (b.row == i) cells[static_cast<std::size_t>(b.column)] = b.text;
    }
    for (std::size_t c = 0; c < cells.size(); ++c) text += (c > 0 ? "," : "") + cells[c];
    text += i % 3 == 0 ? "\r\n" : "\n";
    if (i % 997 == 0) text += "\n";
  }
  return text;
}

// What a read gave: the series and the diagnostics as text.
struct ReadOutcome {
  bool ok = false;
  Series series;
  std::vector<std::string> errors, warnings;
};
ReadOutcome ReadFileAndStrings(const std::string& text, bool from_file,
                               std::size_t two_thread_bytes = kCsvTwoThreadBytes) {
  ReadOutcome r;
  Diagnostics errors, warnings;
  const std::string path = TempPath("large.csv");
  if (from_file) {
    std::ofstream(path, std::ios::binary) << text;
    CsvReadOptions options;
    options.two_thread_bytes = two_thread_bytes;
    r.ok = ReadCanonicalCsv(path, options, &r.series, &errors, &warnings);
    std::filesystem::remove(path);
  } else {
    std::istringstream in(text);
    r.ok = ParseCanonicalCsv(in, path, {}, &r.series, &errors, &warnings);
  }
  for (const Diagnostic& d : errors) r.errors.push_back(d.ToString());
  for (const Diagnostic& d : warnings) r.warnings.push_back(d.ToString());
  return r;
}

// Equal values, NaN equal to NaN.
void ExpectSameColumn(const std::vector<double>& a, const std::vector<double>& b,
                      const char* name) {
  ASSERT_EQ(a.size(), b.size()) << name;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::isnan(a[i]) && std::isnan(b[i])) continue;
    ASSERT_EQ(a[i], b[i]) << name << " row " << i;
  }
}

TEST(CsvRead, ALargeFileReadOnTwoThreadsGivesWhatOnePieceGives) {
  // ReadCanonicalCsv reads a file of kCsvTwoThreadBytes or more in two
  // halves (a helper thread the later one); a stream is read in one piece.
  // Values outside the physical limits in both halves: the first three of a
  // column named with their lines (the blank lines counted), the rest
  // counted, as one reader finds them.
  constexpr int kRows = 60000;
  const std::vector<BadCell> bad = {{5, 5, "999"},      {40000, 5, "999"}, {40001, 5, "998"},
                                    {50000, 5, "997"},  {20, 6, "1e9"},    {59999, 6, "2e9"},
                                    {29999, 4, "9999"}, {30000, 4, "9999"}};
  const std::string text = LargeCsvText(kRows, bad);
  ASSERT_GE(text.size(), 2 * kCsvTwoThreadBytes);
  const ReadOutcome file = ReadFileAndStrings(text, true);
  const ReadOutcome stream = ReadFileAndStrings(text, false);
  ASSERT_TRUE(file.ok) << file.errors.front();
  ASSERT_TRUE(stream.ok);
  EXPECT_EQ(file.series.time_s, stream.series.time_s);
  ASSERT_EQ(file.series.size(), static_cast<std::size_t>(kRows));
  for (const ChannelInfo& info : kChannels) {
    ExpectSameColumn(file.series[info.channel], stream.series[info.channel], info.name.data());
  }
  EXPECT_EQ(file.series.step_s, 60);
  EXPECT_EQ(file.warnings, stream.warnings);
  // t_amb_c 999 at row 40000: line 40000 + 2 (header, 1-based) + 41 blank
  // lines (after rows 0, 997, ..., 39880).
  const std::string named = "large.csv:40043: t_amb_c = 999";
  EXPECT_TRUE(std::any_of(file.warnings.begin(), file.warnings.end(), [&](const std::string& w) {
    return w.find(named) != std::string::npos;
  })) << named;
  EXPECT_TRUE(std::isnan(file.series[Channel::kTAmbC][40000]));
  EXPECT_EQ(file.series[Channel::kPElW][59998], 100 + 59998 % 7 + 0.5);
}

// One time that does not increase, at each row in turn of a small file read
// on two threads: wherever it falls, in a half or at the seam between them,
// the error is the one a reading in one piece gives.
TEST(CsvRead, ATimeThatDoesNotIncreaseIsFoundAtTheSeamToo) {
  constexpr int kRows = 24;
  for (int at = 1; at < kRows; ++at) {
    const std::string text =
        LargeCsvText(kRows, {{at, 0, std::to_string(1700000000 + 60 * (at - 1))}});
    const ReadOutcome file = ReadFileAndStrings(text, true, 1);
    const ReadOutcome stream = ReadFileAndStrings(text, false);
    EXPECT_FALSE(file.ok) << "row " << at;
    EXPECT_EQ(file.errors, stream.errors) << "row " << at;
    ASSERT_EQ(file.errors.size(), 1u) << "row " << at;
    EXPECT_NE(file.errors.front().find("must be later than the time of the row before"),
              std::string::npos)
        << file.errors.front();
  }
}

TEST(CsvRead, ALargeFileWithErrorsReportsThemInLineOrderAsOnePieceDoes) {
  constexpr int kRows = 60000;
  // A malformed number in either half, and times that repeat around the
  // middle of the file, where a reader in two halves would put its seam.
  std::vector<BadCell> bad = {{7, 1, "x"}, {45000, 2, "2,5"}};
  for (int i = 29000; i < 31000; ++i) bad.push_back({i, 0, "1700000000"});
  const std::string text = LargeCsvText(kRows, bad);
  ASSERT_GE(text.size(), 2 * kCsvTwoThreadBytes);
  const ReadOutcome file = ReadFileAndStrings(text, true);
  const ReadOutcome stream = ReadFileAndStrings(text, false);
  EXPECT_FALSE(file.ok);
  EXPECT_EQ(file.errors, stream.errors);
  EXPECT_EQ(file.warnings, stream.warnings);
  ASSERT_FALSE(file.errors.empty());
  EXPECT_NE(file.errors.front().find("large.csv:10: t_in_c = x"), std::string::npos)
      << file.errors.front();
  EXPECT_NE(file.errors.back().find("too many errors"), std::string::npos) << file.errors.back();

  // Only the late malformed number: named at its line, from the later half.
  const ReadOutcome late = ReadFileAndStrings(LargeCsvText(kRows, {{45000, 2, "2,5"}}), true);
  EXPECT_FALSE(late.ok);
  ASSERT_EQ(late.errors.size(), 1u);
  // Line 45000 + 2 + 46 blank lines (after rows 0, 997, ..., 44865).
  EXPECT_NE(late.errors.front().find("large.csv:45048: expected 7 fields, found 8"),
            std::string::npos)
      << late.errors.front();
}

TEST(CsvRead, FlowInLitresPerHourUsesTheConfiguredDensity) {
  const std::string text =
      "time,t_in_c,t_out_c,flow_l_h,g_poa_w_m2,t_amb_c,p_el_w\n1717200000,1,2,360,500,20,100\n";
  Series s;
  Diagnostics errors;
  ASSERT_TRUE(ParseText(text, &s, &errors, CsvReadOptions{.fluid_density_kg_m3 = 1000}));
  EXPECT_DOUBLE_EQ(s[Channel::kMdotKgS][0], 0.1);  // 360 L/h of water
}

TEST(CsvRead, StopsAfterTooManyErrors) {
  std::string text = "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n";
  for (int i = 0; i < 1000; ++i) text += RowTime(i) + ",x,2,0.03,500,20,100\n";
  Series s;
  Diagnostics errors;
  EXPECT_FALSE(ParseText(text, &s, &errors));
  ASSERT_EQ(errors.size(), kMaxCsvErrors + 1);
  EXPECT_EQ(errors.back().ToString(), "in.csv:101: too many errors; reading stopped here");
}

// The reader takes plain decimals of up to 15 digits by a fast path of its
// own (one exact division) and everything else by std::from_chars: both
// must give every cell the same double, and reject the same cells. Random
// cells of every shape around the fast path's edges (15 and 16 digits, a
// point first or last, a sign, exponents, long full-precision numbers),
// all within t_amb_c's physical limits.
TEST(CsvRead, NumbersReadAsStdFromCharsReadsThem) {
  std::mt19937_64 rng(20261125);
  auto digits = [&rng](int n) {
    std::string out;
    for (int i = 0; i < n; ++i) out += static_cast<char>('0' + rng() % 10);
    return out;
  };
  // Signs and points at either end, leading zeros, 15, 16 and 18 digits,
  // an exponent, and cells from_chars rejects.
  std::vector<std::string> cells = {"0",
                                    "-0",
                                    "5.",
                                    ".5",
                                    "-.5",
                                    "-5.",
                                    "007.250",
                                    "1e1",
                                    "12.0000000000000",
                                    "12.00000000000000",
                                    "-59.9999999999999",
                                    "9.99999999999999999",
                                    "-",
                                    ".",
                                    "1.2.3",
                                    "--1",
                                    "0x10",
                                    "1_0"};
  for (int k = 0; k < 4000; ++k) {
    const int int_digits = static_cast<int>(rng() % 3);
    int frac_digits = static_cast<int>(rng() % 18);
    if (int_digits == 0 && frac_digits == 0) frac_digits = 1;
    std::string cell = rng() % 2 ? "-" : "";
    if (int_digits == 2) cell += static_cast<char>('1' + rng() % 5);  // |value| < 60
    if (int_digits >= 1) cell += digits(1);
    if (frac_digits > 0) cell += "." + digits(frac_digits);
    if (rng() % 50 == 0) cell += "e-1";
    cells.push_back(cell);
  }
  const std::string header = "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n";
  std::string accepted_text = header, rejected_text = header;
  std::vector<double> expected;
  std::vector<std::string> accepted, rejected;
  for (const std::string& cell : cells) {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
    const bool ok = ec == std::errc() && end == cell.data() + cell.size();
    std::vector<std::string>& list = ok ? accepted : rejected;
    (ok ? accepted_text : rejected_text) +=
        RowTime(60 * static_cast<std::int64_t>(list.size())) + ",1,2,0.03,500," + cell + ",100\n";
    list.push_back(cell);
    if (ok) expected.push_back(v);
  }
  ASSERT_GE(rejected.size(), 6u);
  ASSERT_LT(rejected.size(), kMaxCsvErrors);

  Series s;
  Diagnostics errors;
  ASSERT_TRUE(ParseText(accepted_text, &s, &errors)) << errors.front().ToString();
  ASSERT_EQ(s.size(), accepted.size());
  for (std::size_t i = 0; i < accepted.size(); ++i) {
    const double got = s[Channel::kTAmbC][i];
    EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(expected[i]))
        << "cell " << accepted[i] << ": read " << got << ", from_chars " << expected[i];
  }

  Series r;
  errors.clear();
  EXPECT_FALSE(ParseText(rejected_text, &r, &errors));
  ASSERT_EQ(errors.size(), rejected.size());
  for (std::size_t i = 0; i < rejected.size(); ++i) {
    EXPECT_EQ(errors[i].ToString(), "in.csv:" + std::to_string(i + 2) +
                                        ": t_amb_c = " + rejected[i] + ": expected a number");
  }
}

TEST(CsvRead, MissingFileIsAnError) {
  Series s;
  Diagnostics errors;
  EXPECT_FALSE(ReadCanonicalCsv("/nonexistent.csv", CsvReadOptions{}, &s, &errors, nullptr));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].ToString(), "/nonexistent.csv: cannot open: No such file or directory");
}

struct RealDay {
  const char* file;
  std::size_t rows;
  std::int64_t first_time_s;
  double first_aoi_deg;
};

class CsvRealData : public ::testing::TestWithParam<RealDay> {};

TEST_P(CsvRealData, LoadsCleanlyWithAllColumns) {
  const RealDay& day = GetParam();
  Series s;
  Diagnostics errors;
  Diagnostics warnings;
  ASSERT_TRUE(ReadCanonicalCsv(kRealDataDir + day.file, CsvReadOptions{.fluid_density_kg_m3 = 1000},
                               &s, &errors, &warnings))
      << errors.front().ToString();
  EXPECT_TRUE(warnings.empty()) << warnings.front().ToString();
  EXPECT_EQ(s.size(), day.rows);
  EXPECT_EQ(s.step_s, 120);
  EXPECT_EQ(s.time_s.front(), day.first_time_s);
  for (const Channel c :
       {Channel::kTInC, Channel::kTOutC, Channel::kMdotKgS, Channel::kGPoaWM2,
        Channel::kGPoaDiffuseWM2, Channel::kAoiRad, Channel::kTAmbC, Channel::kWindMS,
        Channel::kLwDownWM2, Channel::kPElW, Channel::kQThW, Channel::kValid}) {
    ASSERT_TRUE(s.Has(c)) << ChannelName(c);
    EXPECT_EQ(s[c].size(), day.rows);
  }
  EXPECT_FALSE(s.Has(Channel::kGhiWM2));
  EXPECT_DOUBLE_EQ(s[Channel::kAoiRad][0], DegToRad(day.first_aoi_deg));
  // The files hold 12.7° to 107.4° (the sun passes behind the collector
  // plane in the evening); in radians every value is below 2 and some are
  // above 1.5, which degrees would not be.
  std::size_t n_valid = 0;
  double max_aoi_rad = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_GE(s[Channel::kAoiRad][i], DegToRad(12));
    EXPECT_LE(s[Channel::kAoiRad][i], DegToRad(108));
    max_aoi_rad = std::max(max_aoi_rad, s[Channel::kAoiRad][i]);
    EXPECT_NEAR(s[Channel::kMdotKgS][i], 0.033, 0.001);
    n_valid += s[Channel::kValid][i] == 1.0;
  }
  EXPECT_GT(max_aoi_rad, 1.5);
  EXPECT_GT(n_valid, 0u);
}

INSTANTIATE_TEST_SUITE_P(
    CsvHtwSaar, CsvRealData,
    ::testing::Values(RealDay{"day1_clear_low_dT.csv", 306, 1502094241, 43.9403},
                      RealDay{"day3_clear_medium_dT.csv", 341, 1500969360, 60.9237}),
    [](const ::testing::TestParamInfo<RealDay>& info) {
      return std::string(info.param.file).substr(0, 4);
    });

TEST(CsvRealData, PlantConfigOfTheTestBenchLoads) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig(kRealDataDir + "plant.toml", &config, &errors))
      << errors.front().ToString();
  EXPECT_DOUBLE_EQ(config.plant.area_m2, 1.66);
  EXPECT_DOUBLE_EQ(config.plant.tilt_rad, DegToRad(45));
  EXPECT_DOUBLE_EQ(config.plant.fluid_density_kg_m3, 1000);
  EXPECT_DOUBLE_EQ(config.plant.pv_temp_coeff_per_k, -0.0041);
}

}  // namespace
}  // namespace pvtwin
