// Local wall-clock time for the daemon's schedule (the nightly calibration
// at [calibration] at = "02:00" in [calibration] timezone).
//
// The IANA zone becomes the process's TZ, so the C library's tz database
// rules (DST included) apply; the daemon sets it once at start-up and on
// reload, from its one scheduling thread.
#pragma once

#include <cstdint>
#include <string>

namespace pvtwin {

// Makes `iana` the zone of localtime_r for this process. False (and *error)
// when the zone does not exist.
bool UseTimeZone(const std::string& iana, std::string* error);

// The first whole minute strictly after now_s at which the local clock reads
// hour:minute. DST-safe: on a day when that time does not exist (the clock
// jumps over it), the first minute after the jump; on a day when it occurs
// twice (the clock falls back over it), only the first occurrence.
std::int64_t NextLocalTime(std::int64_t now_s, int hour, int minute);

}  // namespace pvtwin
