// Time stamps as text, at the I/O edge: the `time` column of the canonical
// CSV (doc/contracts.md). Inside pvtwin a time is unix seconds UTC (int64).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pvtwin {

// Parses one time cell. Accepted forms, decided per cell:
//   * ISO 8601 date-time with a UTC designator or offset:
//       YYYY-MM-DDTHH:MM[:SS[.fff]](Z|±HH:MM|±HHMM|±HH)
//     ('T' may also be 't' or a space; ',' may separate the fraction).
//     A time without Z or offset is ambiguous and rejected.
//   * unix seconds: [-+]digits[.digits]
// Fractions of a second are dropped towards the past (floor), so a time
// stamp keeps marking the start of its interval. On failure returns false and
// sets *error to the rule that was broken; *unix_s is untouched.
bool ParseTime(std::string_view text, std::int64_t* unix_s, std::string* error);

class NaiveTimeZone;  // io/platform/local_time.h

// As ParseTime, but an ISO 8601 date-time without Z or offset is the local
// time of zone (when zone is not null): in the hour the clocks repeat in
// autumn, the earliest instant after after_s (the row before), so rows that
// count through the hour twice stay in order; a time the clocks skip is an
// error. Times with Z or an offset, and unix seconds, are as ParseTime.
bool ParseTimeIn(std::string_view text, const NaiveTimeZone* zone, std::int64_t after_s,
                 std::int64_t* unix_s, std::string* error);

// A time given on the command line (--from, --to, --train-start, ...): what
// ParseTime accepts, and also
//   * a date YYYY-MM-DD: its 00:00 UTC;
//   * "now", or a time relative to now_s: -14d, -6h, -30m, -90s, +1d
//     (whole numbers; d = 86400 s).
// On failure returns false with the accepted forms in *error.
bool ParseTimeArgument(std::string_view text, std::int64_t now_s, std::int64_t* unix_s,
                       std::string* error);

// "YYYY-MM-DDTHH:MM:SSZ".
std::string FormatIsoUtc(std::int64_t unix_s);

}  // namespace pvtwin
