// The physical limits of the canonical channels (core/data/physical_limits.h) and
// the paths that apply them: the CSV reader, the 1-min aggregation, the
// store's reads; and messages that never echo binary bytes or a 1 MB cell.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "core/common/diagnostic.h"
#include "core/common/units.h"
#include "core/data/aggregate.h"
#include "core/data/physical_limits.h"
#include "core/data/qc.h"
#include "io/files/csv.h"
#include "io/store/store.h"
#include "tests/support/files.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin {
namespace {

TEST(PhysicalLimits, TheTableHoldsThePublishedLimitsAndScalesWithTheArea) {
  // BSRN physically possible long-wave limits (Long & Dutton).
  EXPECT_EQ(PhysicalLimitOf(Channel::kLwDownWM2, 2.0).lo, 40.0);
  EXPECT_EQ(PhysicalLimitOf(Channel::kLwDownWM2, 2.0).hi, 700.0);
  // Recorded air temperature extremes −89.2 °C and 56.7 °C lie inside.
  EXPECT_TRUE(PhysicalLimitOf(Channel::kTAmbC, 2.0).Contains(-89.2));
  EXPECT_TRUE(PhysicalLimitOf(Channel::kTAmbC, 2.0).Contains(56.7));
  EXPECT_FALSE(PhysicalLimitOf(Channel::kTAmbC, 2.0).Contains(-300.0));
  // Per m² limits: P_el ≤ 600 W/m², flow ≤ 1 kg/(s·m²).
  EXPECT_EQ(PhysicalLimitOf(Channel::kPElW, 2.0).hi, 1200.0);
  EXPECT_EQ(PhysicalLimitOf(Channel::kMdotKgS, 2.0).hi, 2.0);
  EXPECT_EQ(PhysicalLimitOf(Channel::kPElW, 0.0).hi, 600.0 * kMaxAreaM2);  // area unknown
  EXPECT_FALSE(PhysicalLimitOf(Channel::kAoiRad, 2.0).Contains(DegToRad(500.0)));
  EXPECT_EQ(DescribeCsvLimit(Channel::kAoiRad, 2.0), "[0, 180] °");  // the CSV edge: degrees
  // Irradiance: down to the ±30 W/m² zero offset a) of the least accurate
  // pyranometer class of ISO 9060, no further; a night reading of −30 W/m²
  // is an offset, −30.5 or −50 W/m² is not.
  for (const Channel c :
       {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaDiffuseWM2}) {
    EXPECT_TRUE(PhysicalLimitOf(c, 2.0).Contains(-30.0)) << ChannelName(c);
    EXPECT_FALSE(PhysicalLimitOf(c, 2.0).Contains(-30.5)) << ChannelName(c);
    EXPECT_FALSE(PhysicalLimitOf(c, 2.0).Contains(-50.0)) << ChannelName(c);
    EXPECT_TRUE(PhysicalLimitOf(c, 2.0).Contains(2500.0)) << ChannelName(c);
  }
  for (const ChannelInfo& info : kChannels) {
    const PhysicalLimit limit = PhysicalLimitOf(info.channel, 1.8);
    EXPECT_LT(limit.lo, limit.hi) << info.name;
    EXPECT_FALSE(limit.Contains(std::numeric_limits<double>::infinity())) << info.name;
    EXPECT_FALSE(limit.Contains(-1e308)) << info.name;
  }
}

// A provider's weather is read against the same table: its air temperature
// against the channel's, the other variables against limits of their own
// (the recorded gust, percentages, BSRN's GHI bound).
// Paper Table 2's night glitch (above 5000 W/m²) passes every edge on the
// short-wave channels, so that ApplyPaperCorrections makes it 0 on every
// path; any other out-of-limit reading does not.
TEST(PhysicalLimits, OnlyTheShortWaveNightGlitchPassesTheEdgeBeyondTheLimits) {
  for (const Channel c : kShortWaveChannels) {
    EXPECT_TRUE(PassesEdge(c, 6000.0, 2.0)) << ChannelName(c);
    EXPECT_TRUE(PassesEdge(c, 800.0, 2.0)) << ChannelName(c);
    EXPECT_FALSE(PassesEdge(c, 3000.0, 2.0)) << ChannelName(c) << ": above BSRN, no glitch";
    EXPECT_FALSE(PassesEdge(c, 1e5, 2.0)) << ChannelName(c) << ": a broken register";
    EXPECT_FALSE(PassesEdge(c, -31.0, 2.0)) << ChannelName(c);
  }
  EXPECT_FALSE(PassesEdge(Channel::kLwDownWM2, 6000.0, 2.0));
  EXPECT_FALSE(PassesEdge(Channel::kTAmbC, 6000.0, 2.0));
  EXPECT_FALSE(PassesEdge(Channel::kPElW, 6000.0, 2.0)) << "600 W/m² × 2 m² at most";
}

TEST(PhysicalLimits, ProviderWeatherLimitsLiveInTheTable) {
  const PhysicalLimit air = ProviderLimitOf(ProviderQuantity::kAirTemperatureC);
  EXPECT_EQ(air.lo, PhysicalLimitOf(Channel::kTAmbC, 0.0).lo);
  EXPECT_EQ(air.hi, PhysicalLimitOf(Channel::kTAmbC, 0.0).hi);
  EXPECT_TRUE(ProviderLimitOf(ProviderQuantity::kWindAt10mMS).Contains(113.0));
  EXPECT_FALSE(ProviderLimitOf(ProviderQuantity::kWindAt10mMS).Contains(-0.1));
  EXPECT_FALSE(ProviderLimitOf(ProviderQuantity::kPercent).Contains(100.5));
  EXPECT_FALSE(ProviderLimitOf(ProviderQuantity::kIrradianceWM2).Contains(-1.0));
  EXPECT_TRUE(ProviderLimitOf(ProviderQuantity::kIrradianceWM2).Contains(1400.0));
}

TEST(PhysicalLimits, ApplyMakesOutOfLimitCellsMissingAndCountsThem) {
  Series s;
  s.time_s = {0, 60, 120};
  s[Channel::kTInC] = {20.0, -300.0, 1e308};
  s[Channel::kWindMS] = {-2.0, 3.0, std::nan("")};
  const LimitViolations v = ApplyPhysicalLimits(&s, 1.8);
  EXPECT_EQ(v.Total(), 3u);
  EXPECT_EQ(v.count[static_cast<std::size_t>(Channel::kTInC)], 2u);
  EXPECT_EQ(v.first_row[static_cast<std::size_t>(Channel::kTInC)], 1u);
  EXPECT_EQ(v.first_value[static_cast<std::size_t>(Channel::kTInC)], -300.0);
  EXPECT_EQ(s[Channel::kTInC][0], 20.0);
  EXPECT_TRUE(std::isnan(s[Channel::kTInC][1]) && std::isnan(s[Channel::kTInC][2]));
  EXPECT_TRUE(std::isnan(s[Channel::kWindMS][0]));
  EXPECT_EQ(s[Channel::kWindMS][1], 3.0);
}

TEST(PhysicalLimits, AggregationRejectsOutOfLimitSamples) {
  std::vector<Sample> samples(12);
  for (int i = 0; i < 12; ++i) {
    Sample& s = samples[static_cast<std::size_t>(i)];
    s.ts_s = 1717236000 + 5 * i;
    s.Set(Channel::kTInC, 20.0);
    s.Set(Channel::kTOutC, 30.0);
    s.Set(Channel::kMdotKgS, 0.03);
    s.Set(Channel::kGPoaWM2, 600.0);
    s.Set(Channel::kTAmbC, i == 4 ? -300.0 : 10.0);
    s.Set(Channel::kPElW, i == 7 ? 1e308 : 150.0);
  }
  AggregateOptions options;
  options.area_m2 = 1.8;
  MinuteRows m;
  std::string error;
  ASSERT_TRUE(AggregateSamples(samples, options, &m, &error)) << error;
  ASSERT_EQ(m.rows.size(), 1u);
  EXPECT_EQ(m.rows[Channel::kTAmbC][0], 10.0);  // the −300 °C sample is left out
  EXPECT_EQ(m.rows[Channel::kPElW][0], 150.0);
  EXPECT_TRUE(m.qc_flags[0] & kQcRejectedValues);
}

// The file path applies the limits once, at its edge: the CSV reader names
// the cell and makes it missing; the samples it gives go through the store
// and the aggregation without a second rejection (no minute flagged
// kQcRejectedValues for it, nothing left for a later ApplyPhysicalLimits to
// count), and the minute is the mean of the other samples.
TEST(PhysicalLimits, ACsvCellOutOfLimitsIsRejectedAndCountedOnceOnItsWayToTheStore) {
  std::ostringstream csv;
  csv << "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n";
  for (int i = 0; i < 12; ++i) {
    csv << "2024-06-01T10:00:" << (i < 2 ? "0" : "") << 5 * i << "Z,20,30,0.03,600,"
        << (i == 4 ? "-300" : std::to_string(10 + i)) << ",150\n";
  }
  std::istringstream in(csv.str());
  CsvReadOptions csv_options;
  csv_options.area_m2 = 1.8;
  Series series;
  Diagnostics errors, warnings;
  ASSERT_TRUE(ParseCanonicalCsv(in, "in.csv", csv_options, &series, &errors, &warnings));
  std::size_t named = 0;
  std::string all;
  for (const Diagnostic& w : warnings) {
    all += w.ToString() + "\n";
    if (w.rule.find("outside") == std::string::npos) continue;
    ++named;
    EXPECT_EQ(w.line, 6);  // the header, then rows 0 … 4
    EXPECT_EQ(w.field, "t_amb_c");
  }
  EXPECT_EQ(named, 1u) << all;
  ASSERT_EQ(series.size(), 12u);
  EXPECT_TRUE(std::isnan(series[Channel::kTAmbC][4]));
  Series again = series;
  EXPECT_EQ(ApplyPhysicalLimits(&again, 1.8).Total(), 0u);

  testing::ScratchDir dir("limits_csv_once");
  StoreOptions options;
  options.aggregate.area_m2 = 1.8;
  std::string error;
  std::unique_ptr<Store> store = Store::Open((dir / "pvtwin.db").string(), options, &error);
  ASSERT_TRUE(store) << error;
  ASSERT_TRUE(store->InsertSamples(SamplesFromSeries(series), &error)) << error;
  int written = 0;
  ASSERT_TRUE(store->AggregateMinutes(series.time_s.back() + 60, &written, &error)) << error;
  ASSERT_EQ(written, 1);
  MinuteRows minutes;
  ASSERT_TRUE(
      store->ReadMinuteRows(series.time_s.front(), series.time_s.back() + 60, &minutes, &error))
      << error;
  ASSERT_EQ(minutes.rows.size(), 1u);
  EXPECT_EQ(minutes.n_samples[0], 12);
  EXPECT_FALSE(minutes.qc_flags[0] & kQcRejectedValues);
  // The mean of 10 … 21 °C without the rejected sample's 14 °C.
  double sum = 0.0;
  for (int i = 0; i < 12; ++i) sum += i == 4 ? 0.0 : 10.0 + i;
  EXPECT_NEAR(minutes.rows[Channel::kTAmbC][0], sum / 11.0, 1e-9);
  EXPECT_EQ(minutes.rows[Channel::kPElW][0], 150.0);
}

TEST(PhysicalLimits, StoreReadsLeaveOutRowsOtherProgramsWroteOutOfLimits) {
  testing::ScratchDir dir("limits_store");
  const std::string path = (dir / "pvtwin.db").string();
  StoreOptions options;
  options.aggregate.area_m2 = 1.8;
  std::string error;
  std::unique_ptr<Store> store = Store::Open(path, options, &error);
  ASSERT_TRUE(store) << error;
  testing::RawDb db(path);
  db.Exec(
      "INSERT INTO weather_forecast(ts, g_poa_w_m2, t_amb_c, wind_m_s) VALUES "
      "(1717236000, 500, 20, 2), (1717236060, 510, 1e30, -4)");
  Series weather;
  ASSERT_TRUE(store->ReadWeatherForecast(1717236000, 1717236120, &weather, &error)) << error;
  ASSERT_EQ(weather.size(), 2u);
  EXPECT_EQ(weather[Channel::kTAmbC][0], 20.0);
  EXPECT_TRUE(std::isnan(weather[Channel::kTAmbC][1]));
  EXPECT_TRUE(std::isnan(weather[Channel::kWindMS][1]));
  EXPECT_EQ(weather[Channel::kGPoaWM2][1], 510.0);
}

TEST(Messages, AHugeOrBinaryCellIsCutAndEscaped) {
  const std::string huge(1 << 20, '9');
  std::istringstream in(
      "time,t_in_c,t_out_c,flow_kg_s,g_poa_w_m2,t_amb_c,p_el_w\n"
      "2024-06-01T10:00:00Z,27.87,30.76,0.0332,750.08," +
      huge + ",177.78\n");
  Series s;
  Diagnostics errors;
  EXPECT_FALSE(ParseCanonicalCsv(in, "big.csv", CsvReadOptions{}, &s, &errors, nullptr));
  ASSERT_EQ(errors.size(), 1u);
  const std::string message = errors[0].ToString();
  EXPECT_LT(message.size(), 200u) << message.substr(0, 300);
  EXPECT_NE(message.find("... (1048576 bytes)"), std::string::npos) << message;
  EXPECT_EQ(PrintableExcerpt(std::string("a\x01\xff\xc3\xa9\x1b[31m")), "a\\x01\\xFFé\\x1B[31m");
}

}  // namespace
}  // namespace pvtwin
