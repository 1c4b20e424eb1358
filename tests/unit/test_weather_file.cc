// Weather-forecast files (io/weather/weather_file.h): the recorded Open-Meteo
// answers and a canonical CSV in tests/weather/data, and malformed variants
// of them; every error names the file, the field (with its index) and what
// was expected.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "io/weather/weather_file.h"
#include "tests/support/files.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
const fs::path kData = fs::path(PVTWIN_SOURCE_DIR) / "tests" / "weather" / "data";

std::string Recorded(const std::string& name) { return testing::ReadFile(kData / name); }

// All errors of parsing text, one per line.
std::string ErrorsOf(const std::string& text, const std::string& name = "f.json") {
  WeatherFile file;
  Diagnostics errors;
  EXPECT_FALSE(ParseWeatherFile(text, name, &file, &errors));
  std::string all;
  for (const Diagnostic& d : errors) all += d.ToString() + "\n";
  return all;
}

// The recorded hourly answer with one change.
std::string Hourly(const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = nlohmann::json::parse(Recorded("open-meteo-hourly.json"));
  edit(j);
  return j.dump();
}

TEST(WeatherFile, ReadsOpenMeteoHourlyWithKmPerHourWind) {
  WeatherFile file;
  Diagnostics errors;
  ASSERT_TRUE(ParseWeatherFile(Recorded("open-meteo-hourly.json"), "h.json", &file, &errors))
      << errors.front().ToString();
  const ProviderWeather& w = file.weather;
  EXPECT_EQ(file.format, "Open-Meteo JSON, hourly");
  ASSERT_EQ(w.time_s.size(), 48u);
  EXPECT_EQ(w.time_s.front(), 1717200000);  // 2024-06-01T00:00 GMT
  EXPECT_EQ(w.step_s, 3600.0);
  EXPECT_EQ(w.irradiance_offset_s, -3600.0);  // radiation: mean of the preceding hour
  EXPECT_EQ(w.instant_offset_s, 0.0);
  // wind_speed_10m is in km/h in this file: 5.4 km/h = 1.5 m/s, 13.7 km/h = 3.8056 m/s.
  EXPECT_NEAR(w.wind_m_s[0], 1.5, 1e-12);
  EXPECT_NEAR(w.wind_m_s[13], 13.7 / 3.6, 1e-12);
  EXPECT_EQ(w.ghi_w_m2[12], 850.0);
  EXPECT_EQ(w.dhi_w_m2[12], 115.0);
  EXPECT_EQ(w.dew_point_c.size(), 48u);
  EXPECT_EQ(w.cloud_cover_pct[30], 60.0);
  EXPECT_EQ(file.missing_values, 0u);
}

// minutely_15 in local time of Europe/Vienna (CEST): 10:00 local = 08:00 UTC;
// wind in m/s; the null temperature is a missing value, reported.
TEST(WeatherFile, ReadsOpenMeteo15MinutelyInLocalTimeWithANull) {
  WeatherFile file;
  Diagnostics errors;
  ASSERT_TRUE(ParseWeatherFile(Recorded("open-meteo-15min.json"), "q.json", &file, &errors));
  const ProviderWeather& w = file.weather;
  EXPECT_EQ(file.format, "Open-Meteo JSON, minutely_15");
  EXPECT_EQ(w.time_s.front(), 1717228800);  // 2024-06-01T08:00:00Z
  EXPECT_EQ(w.step_s, 900.0);
  EXPECT_EQ(w.irradiance_offset_s, -900.0);
  EXPECT_EQ(w.wind_m_s[0], 2.1);
  EXPECT_EQ(w.dni_w_m2[0], 710.0);
  EXPECT_TRUE(std::isnan(w.t_amb_c[5]));
  EXPECT_EQ(file.missing_values, 1u);
  ASSERT_EQ(file.notes.size(), 1u);
  EXPECT_NE(file.notes[0].find("minutely_15.temperature_2m: 1 null values"), std::string::npos)
      << file.notes[0];
}

// Without a zone the tz database knows, the fixed utc_offset_seconds holds:
// 00:00 at +01:00 is 23:00 UTC the day before; unix times need neither.
TEST(WeatherFile, FallsBackToTheFixedUtcOffset) {
  WeatherFile file;
  Diagnostics errors;
  ASSERT_TRUE(ParseWeatherFile(Hourly([](auto& j) {
                                 j.erase("timezone");
                                 j["utc_offset_seconds"] = 3600;
                               }),
                               "o.json", &file, &errors));
  EXPECT_EQ(file.weather.time_s.front(), 1717200000 - 3600);
  nlohmann::json unix_times = nlohmann::json::array();
  for (int i = 0; i < 48; ++i) unix_times.push_back(1717200000 + 3600 * i);
  ASSERT_TRUE(ParseWeatherFile(Hourly([&](auto& j) {
                                 j["timezone"] = "Europe/Vienna";
                                 j["hourly"]["time"] = unix_times;
                               }),
                               "u.json", &file, &errors));
  EXPECT_EQ(file.weather.time_s.front(), 1717200000);
}

TEST(WeatherFile, ReadsTheCanonicalCsvAsIntervalMeans) {
  WeatherFile file;
  Diagnostics errors;
  ASSERT_TRUE(ParseWeatherFile(Recorded("weather.csv"), "w.csv", &file, &errors))
      << errors.front().ToString();
  const ProviderWeather& w = file.weather;
  EXPECT_EQ(file.format, "canonical CSV");
  EXPECT_EQ(w.step_s, 900.0);
  EXPECT_EQ(w.irradiance_offset_s, 0.0);  // time marks the interval's start
  EXPECT_EQ(w.instant_offset_s, 450.0);
  EXPECT_EQ(w.gti_w_m2[0], 905.0);
  EXPECT_TRUE(std::isnan(w.gti_w_m2[3]));
  EXPECT_EQ(w.t_sky_c[4], 4.3);
  EXPECT_EQ(file.missing_values, 1u);
}

TEST(WeatherFile, UnknownUnitNamesTheField) {
  const std::string e = ErrorsOf(Recorded("open-meteo-wrong-units.json"), "u.json");
  EXPECT_NE(e.find("u.json: hourly_units.wind_speed_10m = \"mph\": unknown unit: expected "
                   "\"m/s\" or \"km/h\""),
            std::string::npos)
      << e;
  const std::string f =
      ErrorsOf(Hourly([](auto& j) { j["hourly_units"]["temperature_2m"] = "°F"; }));
  EXPECT_NE(f.find("hourly_units.temperature_2m = \"°F\": unknown unit: expected \"°C\""),
            std::string::npos)
      << f;
  const std::string g =
      ErrorsOf(Hourly([](auto& j) { j["hourly_units"].erase("wind_speed_10m"); }));
  EXPECT_NE(g.find("hourly_units.wind_speed_10m: missing"), std::string::npos) << g;
}

TEST(WeatherFile, TruncatedJsonSaysWhere) {
  const std::string text = Recorded("open-meteo-hourly.json").substr(0, 700);
  const std::string e = ErrorsOf(text, "t.json");
  EXPECT_NE(e.find("t.json: truncated JSON"), std::string::npos) << e;
  const std::string g = ErrorsOf("{\"hourly\": {\"time\": [1, 2,, 3]}}", "g.json");
  EXPECT_NE(g.find("g.json: not valid JSON at byte"), std::string::npos) << g;
}

TEST(WeatherFile, ArraysOfAnotherLengthNameBothFields) {
  const std::string e = ErrorsOf(Hourly([](auto& j) { j["hourly"]["temperature_2m"].erase(47); }));
  EXPECT_NE(e.find("hourly.temperature_2m: 47 values, but hourly.time has 48"), std::string::npos)
      << e;
}

TEST(WeatherFile, MissingArraysAndBlocksAreErrors) {
  EXPECT_NE(ErrorsOf(Hourly([](auto& j) {
              j["hourly"].erase("time");
            })).find("hourly.time: missing: expected an array of time stamps"),
            std::string::npos);
  EXPECT_NE(ErrorsOf(Hourly([](auto& j) { j.erase("hourly"); })).find("hourly: missing"),
            std::string::npos);
  const std::string none = ErrorsOf(Hourly([](auto& j) {
    nlohmann::json time = j["hourly"]["time"];
    j["hourly"] = {{"time", time}, {"snowfall", nlohmann::json::array()}};
  }));
  EXPECT_NE(none.find("no weather variable pvtwin reads"), std::string::npos) << none;
}

TEST(WeatherFile, NonMonotonicAndUnevenTimesNameTheIndex) {
  const std::string back =
      ErrorsOf(Hourly([](auto& j) { j["hourly"]["time"][10] = "2024-06-01T08:00"; }));
  EXPECT_NE(back.find("hourly.time[10] = \"2024-06-01T08:00\": must be later than hourly.time[9]"),
            std::string::npos)
      << back;
  const std::string gap =
      ErrorsOf(Hourly([](auto& j) { j["hourly"]["time"][10] = "2024-06-01T10:30"; }));
  EXPECT_NE(gap.find("hourly.time[10]"), std::string::npos) << gap;
  EXPECT_NE(gap.find("evenly spaced"), std::string::npos) << gap;
}

// A file that would become millions of 1-min rows is refused, not imported.
TEST(WeatherFile, RefusesStepsOverAnHourSpansOver100DaysAndFarTimes) {
  const std::string units = R"("hourly_units":{"temperature_2m":"°C"})";
  const std::string coarse =
      ErrorsOf("{" + units + R"(,"hourly":{"time":[0,10800],"temperature_2m":[1,2]}})", "s.json");
  EXPECT_NE(coarse.find("s.json: hourly.time: a step of 10800 s: expected at most 3600 s"),
            std::string::npos)
      << coarse;
  std::string times = "0", temps = "1";
  for (int i = 1; i <= 2500; ++i) {
    times += "," + std::to_string(i * 3600);
    temps += ",1";
  }
  const std::string long_file = ErrorsOf("{" + units + R"(,"hourly":{"time":[)" + times +
                                         R"(],"temperature_2m":[)" + temps + "]}}");
  EXPECT_NE(long_file.find("spans 104 days: expected at most 100 days"), std::string::npos)
      << long_file;
  const std::string far =
      ErrorsOf("{" + units + R"(,"hourly":{"time":[9000000000000000000,9000000000000003600],)" +
               R"("temperature_2m":[1,2]}})");
  EXPECT_NE(far.find("hourly.time[0] = 9000000000000000000: expected a time between 1970 and 2100"),
            std::string::npos)
      << far;
}

TEST(WeatherFile, AStringWhereANumberBelongsNamesTheIndex) {
  const std::string e =
      ErrorsOf(Hourly([](auto& j) { j["hourly"]["shortwave_radiation"][7] = "430"; }));
  EXPECT_NE(e.find("hourly.shortwave_radiation[7] = \"430\": expected a number or null"),
            std::string::npos)
      << e;
}

TEST(WeatherFile, NullsAreMissingNotZero) {
  WeatherFile file;
  Diagnostics errors;
  const std::string text = Hourly([](auto& j) {
    j["hourly"]["shortwave_radiation"][11] = nullptr;
    j["hourly"]["wind_speed_10m"][3] = nullptr;
  });
  ASSERT_TRUE(ParseWeatherFile(text, "n.json", &file, &errors));
  EXPECT_TRUE(std::isnan(file.weather.ghi_w_m2[11]));
  EXPECT_TRUE(std::isnan(file.weather.wind_m_s[3]));
  EXPECT_EQ(file.missing_values, 2u);
  EXPECT_EQ(file.notes.size(), 2u);
}

// Values outside the physical limits of a provider's variables
// (core/data/physical_limits.h, ProviderLimitOf) are missing with one note
// per variable; the limits themselves are kept (1500 W/m², 100 %, 113 m/s).
TEST(WeatherFile, ValuesOutsideThePhysicalLimitsAreMissingWithANote) {
  WeatherFile file;
  Diagnostics errors;
  const std::string text = Hourly([](auto& j) {
    j["hourly_units"]["wind_speed_10m"] = "m/s";
    j["hourly"]["shortwave_radiation"][11] = 1500.5;
    j["hourly"]["shortwave_radiation"][12] = 1500;
    j["hourly"]["cloud_cover"][4] = 100.5;
    j["hourly"]["cloud_cover"][5] = 100;
    j["hourly"]["wind_speed_10m"][3] = 113.5;
    j["hourly"]["wind_speed_10m"][6] = 113;
    j["hourly"]["temperature_2m"][2] = 60.5;
  });
  ASSERT_TRUE(ParseWeatherFile(text, "l.json", &file, &errors));
  EXPECT_TRUE(std::isnan(file.weather.ghi_w_m2[11]));
  EXPECT_EQ(file.weather.ghi_w_m2[12], 1500.0);
  EXPECT_TRUE(std::isnan(file.weather.cloud_cover_pct[4]));
  EXPECT_EQ(file.weather.cloud_cover_pct[5], 100.0);
  EXPECT_TRUE(std::isnan(file.weather.wind_m_s[3]));
  EXPECT_EQ(file.weather.wind_m_s[6], 113.0);
  EXPECT_TRUE(std::isnan(file.weather.t_amb_c[2]));
  EXPECT_EQ(file.missing_values, 4u);
  ASSERT_EQ(file.notes.size(), 4u);
  for (const std::string& note : file.notes) {
    EXPECT_NE(note.find(": 1 values outside the physical limits, read as missing"),
              std::string::npos)
        << note;
  }
}

TEST(WeatherFile, CsvErrorsNameLineAndColumn) {
  const std::string e = ErrorsOf("time,t_amb_c\n2024-06-01T10:00:00Z,20\n", "c.csv");
  EXPECT_NE(e.find("c.csv:1: g_poa_w_m2: required column missing"), std::string::npos) << e;
  const std::string f = ErrorsOf(
      "time,g_poa_w_m2,t_amb_c\n2024-06-01T10:00:00Z,900,20\n2024-06-01T10:15:00Z,abc,20\n",
      "d.csv");
  EXPECT_NE(f.find("d.csv:3: g_poa_w_m2 = abc"), std::string::npos) << f;
  const std::string g = ErrorsOf(
      "time,g_poa_w_m2,t_amb_c\n2024-06-01T10:00:00Z,900,20\n2024-06-01T10:15:00Z,900,20\n"
      "2024-06-01T10:20:00Z,900,20\n",
      "e.csv");
  EXPECT_NE(g.find("e.csv:4: time"), std::string::npos) << g;
  EXPECT_NE(ErrorsOf("", "empty.csv").find("empty file"), std::string::npos);
}

}  // namespace
}  // namespace pvtwin
