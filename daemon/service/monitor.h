// The daemon's daily checks (core/monitoring.h), run after each nightly
// calibration: forecast_skill materialised for the days that ended or
// changed, the performance index of every day of the window not yet
// scored, sensor faults of the last two days, the drift of the accepted
// parameters and the performance alarm, on the window's 1-min rows or,
// without them, its measurement_interval rows at their step (window_data.h).
// Results go to the store (forecast_skill_day, performance_daily, qc_event,
// monitor_event); what an operator must see is also returned as log lines.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "config/plant_config.h"
#include "core/model/variant.h"
#include "io/store/store.h"

namespace pvtwin::cli {

struct DailyCheckInputs {
  const Config* config = nullptr;
  ModelSpec spec;
  std::int64_t now_s = 0;
  // The calibration that ran this night was accepted: its parameters are new
  // and the drift check looks at them.
  bool accepted_now = false;
};

// (journald priority, line) pairs for the log; storage errors included.
std::vector<std::pair<int, std::string>> RunDailyChecks(Store& store, const DailyCheckInputs& in);

// The first day of the plant's newest change that a performance alarm saw
// (ChangeOnsetS over the days the alarm looks back on, the later of the two
// outputs'), -1 when neither alarmed there; false on a storage error.
// *outputs (when given): the outputs whose alarms dated that change, in
// `pvtwin diagnose --objective`'s words: "p_el", "q_th", "both" ("": none).
bool NewestChangeOnset(Store& store, const DailyCheckInputs& in, std::int64_t* onset_s,
                       std::string* error, std::string* outputs = nullptr);

}  // namespace pvtwin::cli
