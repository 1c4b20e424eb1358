// The daemon's diagnosis of the sim-to-real gap (core/diagnosis.h), run after
// a nightly calibration on its window as a child process
// (`pvtwin diagnose --db … --record`), so that a slow or failing diagnosis
// never holds up polling: at most once every [diagnosis] every_days (after a
// performance alarm nightly, on the days since the change: PlanFor), stopped
// after timeout_s. The child writes its diagnosis row itself; the HTML report
// is kept as <state dir>/reports/diagnosis-<date>.html, the newest `keep` of
// them. Failures and timeouts become monitor_event rows and log lines.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "config/plant_config.h"
#include "core/physics/solar_position.h"
#include "io/platform/child_process.h"
#include "io/store/store.h"

namespace pvtwin::cli {

using LogFn = std::function<void(int priority, const std::string& line)>;

class NightlyDiagnosis {
 public:
  struct Job {
    std::string exe, config_path, db_path, variant;
    std::string step_s = "60";  // the calibration's model step
    std::int64_t window_start = 0, window_end = 0;
    std::int64_t calibration_id = 0;
    std::int64_t now_s = 0;  // the daemon's clock (simulated under --speed)
    // The first day of the plant's newest change that a performance alarm
    // saw (monitor.h NewestChangeOnset); 0 or less: none.
    std::int64_t change_from = 0;
    // The outputs whose alarms dated that change ("p_el", "q_th", "both";
    // NewestChangeOnset): the diagnosis of the days since judges the
    // candidates on them (`diagnose --objective`). "": both.
    std::string change_outputs;
    std::int64_t solar_offset_s = 0;  // SolarDayOffsetS of the plant
    SolarPositionInput site;          // SiteAtStandardPressure of the plant
  };

  // Whether a job starts tonight, and on which days (Plan). A change the
  // alarm saw inside the calibration window, with at least the two days
  // the diagnosis needs after it (a training and a held-out day), moves
  // the window's start to the change: a model fitted across it judges
  // neither state (the week of doc/validation.md: clipping from the week's
  // first day is not among the candidates on the 14 days, and named on the
  // days since). The diagnosis of a change runs every night, whatever
  // every_days, while the change lies inside the window: each night adds a
  // day of the changed plant, and a verdict on a few days is a low-confidence
  // one (hours as units), not one to stop on. Otherwise at most once every
  // every_days.
  //
  // The diagnosis splits its data by local solar day (core/diagnosis/
  // diagnosis.h): both ends of its window move to the nearest local solar
  // midnight, when the sun is down, so that every day it judges is a whole
  // one. The calibration's window ends at the night's run (02:00 local, an
  // hour or two past solar midnight in Europe): without this the hours since
  // solar midnight, all dark, were a held-out day of their own, and with two
  // days since a change the only one.
  struct Plan {
    bool start = false;
    std::int64_t window_start = 0, window_end = 0;
    std::string why;  // for the log: why the window starts there ("" the calibration's)
    bool since_change = false;  // the window starts at the change
  };
  static Plan PlanFor(const DiagnosisConfig& config, const Store::DiagnosisRow* last,
                      const Job& job);

  // The plant before the change of a plan on the days since one: the newest
  // accepted calibration whose window ended before the sun rose on the
  // change's first day (its dark hours hold nothing of the changed plant).
  // *found false without one, or when the plan is not on the days since a
  // change.
  static bool CalibrationBeforeChange(Store& store, const Plan& plan, const Job& job,
                                      Store::CalibrationRow* row, bool* found, std::string* error);

  // state_dir holds reports/ and the child's scratch folder diagnosis/.
  explicit NightlyDiagnosis(std::filesystem::path state_dir) : state_dir_(std::move(state_dir)) {}

  // Starts the child when enabled, none is running and PlanFor says so, on
  // the days PlanFor gives. On the days since a change it judges the
  // effects against the plant before it (CalibrationBeforeChange; `diagnose
  // --against-calibration`, DiagnosisOptions::reference_params, and the days
  // of its window, reference_days), so that the structure the plant had all
  // along does not compete with what changed.
  void MaybeStart(const DiagnosisConfig& config, Store& store, const Job& job, const LogFn& log);
  // Non-blocking: a finished child's report is kept and its verdict logged;
  // a child past timeout_s is killed.
  void Check(const DiagnosisConfig& config, Store& store, const LogFn& log);
  // Kills a running child (daemon shutdown).
  void Stop();
  bool running() const { return child_.running(); }

 private:
  void Finish(int exit_code, const DiagnosisConfig& config, Store& store, const LogFn& log);
  void Event(Store& store, const std::string& kind, const std::string& message, const LogFn& log);

  std::filesystem::path state_dir_;
  ChildProcess child_;
  double started_wall_s_ = 0.0;
  std::int64_t job_now_s_ = 0;
};

}  // namespace pvtwin::cli
