// The measurements of a time window from the store, for the jobs that fit,
// check or diagnose the plant (the nightly calibration, the daily checks,
// `pvtwin diagnose --db`): the 1-min rows of measurement_1min when the window
// has any, else the rows of measurement_interval (2-, 10-, 15-min logger data
// from `pvtwin import`) at their own step. Interval rows are never split into
// 1-min rows: that would invent what happened inside each interval; the
// model runs at the interval's step instead, as `pvtwin calibrate --csv`
// does with such a CSV.
#pragma once

#include <cstdint>
#include <string>

#include "io/store/store.h"

namespace pvtwin::cli {

enum class WindowSource {
  kNone,       // neither table has a row in the window
  kMinutes,    // measurement_1min, step 60 s
  kIntervals,  // measurement_interval, at its own step (rows.step_s)
};

struct WindowData {
  Series rows;  // from_ts <= ts < to_ts, in time order; step_s as the source's
  WindowSource source = WindowSource::kNone;
  // "measurement_1min", "measurement_interval" or "" (kNone).
  const char* Table() const;
  // For a log line: "1-min rows" or "N-min rows of measurement_interval".
  std::string Describe() const;
};

// Reads the window [from_ts, to_ts). One source per window: any 1-min row
// makes it kMinutes (the rows polled or imported at 1 min are the finer
// data). Interval rows of several steps in one window take the most common
// step (Store::ReadIntervalRows). False (and *error) when the store fails.
bool ReadWindowData(Store& store, std::int64_t from_ts, std::int64_t to_ts, WindowData* out,
                    std::string* error);

// The model step for data of step data_step_s when step_s is asked for
// (0: the data's own): step_s when it is a whole multiple of the data's
// step (the data are averaged to it), else the data's step. The daemon's
// [calibration] step_s of 60 s then runs 2-min data at 120 s.
double StepForData(double step_s, double data_step_s);

}  // namespace pvtwin::cli
