// Local wall-clock time for the daemon's schedule (the nightly calibration
// at [calibration] at = "02:00" in [calibration] timezone).
//
// The IANA zone becomes the process's TZ, so the C library's tz database
// rules (DST included) apply; the daemon sets it once at start-up and on
// reload, from its one scheduling thread.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pvtwin {

// Makes `iana` the zone of NextLocalTime (the daemon's schedule) and of
// localtime_r for this process. False (and *error) when the zone does not
// exist.
bool UseTimeZone(const std::string& iana, std::string* error);

// The first whole minute strictly after now_s at which the local clock reads
// hour:minute. DST-safe: on a day when that time does not exist (the clock
// jumps over it), the first minute after the jump; on a day when it occurs
// twice (the clock falls back over it), only the first occurrence.
std::int64_t NextLocalTime(std::int64_t now_s, int hour, int minute);

// A civil day of a zone: its date and the UTC instants [start_s, end_s) it
// spans, from one local midnight to the next: 24 h, or 23 h / 25 h on the
// days daylight saving time begins / ends.
struct LocalDay {
  std::string date;  // "YYYY-MM-DD", the local civil date
  std::int64_t start_s = 0, end_s = 0;
};

// The civil days of the zone iana that overlap [from_s, to_s), in time order
// (none when to_s <= from_s). "UTC" is reckoned without the process's zone;
// any other zone is made the process's TZ first unless it already is (as
// UseTimeZone, so not while another thread reads local time: the daemon
// sets the same zone at start-up). A day that starts at a time the clock
// skips begins at the first instant after the jump. False and *error when
// the zone does not exist.
bool LocalDaysOverlapping(const std::string& iana, std::int64_t from_s, std::int64_t to_s,
                          std::vector<LocalDay>* days, std::string* error);

// The zone of naive time stamps: "2024-06-01 12:00" written by a logger that
// keeps local time and says nothing about it. Either a zone of the tz
// database (daylight saving time included; Resolve uses it without changing
// the zone of NextLocalTime) or a fixed offset from UTC, "+01:00", "-05:30",
// "UTC+1" (for a logger that keeps standard time all year). Safe to use on
// any thread: every local-time function here holds one lock while it sets
// and reads the process's TZ.
class NaiveTimeZone {
 public:
  // nullopt and *error (naming the accepted forms) when text is neither.
  static std::optional<NaiveTimeZone> Parse(const std::string& text, std::string* error);

  // The UTC instants at which the local clock reads wall_s (the local date
  // and time counted as if they were UTC seconds), earliest first: none in
  // the hour the clocks skip in spring, two in the hour they repeat in
  // autumn, one otherwise. Returns how many were written to utc_s.
  int Resolve(std::int64_t wall_s, std::int64_t utc_s[2]) const;

  const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::optional<int> fixed_offset_s_;  // set for a fixed offset
};

}  // namespace pvtwin
