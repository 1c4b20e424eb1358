// The nightly schedule (io/platform/local_time.h) in Europe/Vienna across both DST
// changes of 2024 (EU rule: last Sunday of March and October, 01:00 UTC).
// Expected instants are written as UTC calendar times.
#include "io/platform/local_time.h"

#include <gtest/gtest.h>

#include <ctime>
#include <optional>
#include <vector>

#include "config/plant_config.h"

namespace pvtwin {
namespace {

std::int64_t Utc(int year, int month, int day, int hour, int minute = 0) {
  std::tm tm{};
  tm.tm_year = year - 1900;
  tm.tm_mon = month - 1;
  tm.tm_mday = day;
  tm.tm_hour = hour;
  tm.tm_min = minute;
  return static_cast<std::int64_t>(::timegm(&tm));
}

class LocalTime : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    ASSERT_TRUE(UseTimeZone("Europe/Vienna", &error)) << error;
  }
};

TEST_F(LocalTime, SummerNightIsTwoHoursAheadOfUtc) {
  EXPECT_EQ(NextLocalTime(Utc(2024, 6, 1, 12), 2, 0), Utc(2024, 6, 2, 0));
}

TEST_F(LocalTime, WinterNightIsOneHourAheadOfUtc) {
  EXPECT_EQ(NextLocalTime(Utc(2024, 1, 10, 12), 2, 0), Utc(2024, 1, 11, 1));
}

TEST_F(LocalTime, StrictlyAfterNow) {
  EXPECT_EQ(NextLocalTime(Utc(2024, 6, 2, 0), 2, 0), Utc(2024, 6, 3, 0));
}

TEST_F(LocalTime, SpringForwardRunsRightAfterTheSkippedHour) {
  // 31 March 2024: 02:00 CET does not exist, the clock jumps to 03:00 CEST
  // at 01:00 UTC. The run happens then, once.
  EXPECT_EQ(NextLocalTime(Utc(2024, 3, 30, 23), 2, 0), Utc(2024, 3, 31, 1));
  EXPECT_EQ(NextLocalTime(Utc(2024, 3, 31, 1), 2, 0), Utc(2024, 4, 1, 0));
}

TEST_F(LocalTime, FallBackRunsOnlyAtTheFirstOccurrence) {
  // 27 October 2024: 02:00–02:59 happens twice (CEST, then CET from 01:00 UTC).
  EXPECT_EQ(NextLocalTime(Utc(2024, 10, 26, 22), 2, 0), Utc(2024, 10, 27, 0));
  EXPECT_EQ(NextLocalTime(Utc(2024, 10, 27, 0, 30), 2, 0), Utc(2024, 10, 28, 1));
}

TEST_F(LocalTime, Midnight) {
  EXPECT_EQ(NextLocalTime(Utc(2024, 6, 1, 12), 0, 0), Utc(2024, 6, 1, 22));
}

// A weather file's naive times in another zone (Open-Meteo with
// timezone=GMT, read on the daemon's weather thread) must not move the
// schedule: the nightly run stays at 02:00 in Vienna.
TEST_F(LocalTime, ANaiveZoneReadElsewhereLeavesTheScheduleZone) {
  std::string error;
  const std::optional<NaiveTimeZone> gmt = NaiveTimeZone::Parse("America/New_York", &error);
  ASSERT_TRUE(gmt.has_value()) << error;
  std::int64_t utc[2] = {0, 0};
  ASSERT_EQ(gmt->Resolve(Utc(2024, 1, 10, 12), utc), 1);  // 12:00 in New York: 17:00 UTC
  EXPECT_EQ(utc[0], Utc(2024, 1, 10, 17));
  EXPECT_EQ(NextLocalTime(Utc(2024, 1, 10, 12), 2, 0), Utc(2024, 1, 11, 1));
  std::vector<LocalDay> days;
  ASSERT_TRUE(LocalDaysOverlapping("Asia/Tokyo", Utc(2024, 1, 10, 0), Utc(2024, 1, 10, 1), &days,
                                   &error))
      << error;
  ASSERT_EQ(days.size(), 1u);
  EXPECT_EQ(days[0].start_s, Utc(2024, 1, 9, 15));  // Tokyo's midnight, UTC+9
  EXPECT_EQ(NextLocalTime(Utc(2024, 6, 1, 12), 2, 0), Utc(2024, 6, 2, 0));
  ASSERT_EQ(gmt->Resolve(Utc(2024, 6, 10, 12), utc), 1);  // daylight saving time: UTC-4
  EXPECT_EQ(utc[0], Utc(2024, 6, 10, 16));
}

TEST(TimeZone, UnknownZonesAreRejected) {
  std::string error;
  EXPECT_FALSE(UseTimeZone("Europe/Atlantis", &error));
  EXPECT_NE(error.find("Europe/Atlantis"), std::string::npos);
  EXPECT_FALSE(TimeZoneExists("../etc/passwd"));
  EXPECT_TRUE(TimeZoneExists("UTC"));
}

TEST(ClockTime, ParsesOnlyValidTimes) {
  int h = -1, m = -1;
  EXPECT_TRUE(ParseClockTime("02:30", &h, &m));
  EXPECT_EQ(h, 2);
  EXPECT_EQ(m, 30);
  EXPECT_FALSE(ParseClockTime("24:00", &h, &m));
  EXPECT_FALSE(ParseClockTime("2:30", &h, &m));
  EXPECT_FALSE(ParseClockTime("02:60", &h, &m));
}

}  // namespace
}  // namespace pvtwin
