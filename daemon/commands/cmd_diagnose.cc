// pvtwin diagnose: where a model's held-out error lies, which catalogued
// effect it misses and how far the error shrinks with it (core/diagnosis.h);
// pvtwin diagnose-selftest: the proof on withheld effects
// (core/diagnosis_selftest.h).
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/common/clock.h"
#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/diagnosis_selftest.h"
#include "core/monitor/monitoring.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/store_cli.h"
#include "daemon/service/window_data.h"
#include "io/files/params_json.h"
#include "io/platform/quantity_text.h"
#include "io/platform/time_format.h"
#include "io/report/diagnosis_report.h"
#include "io/store/store.h"

namespace pvtwin::cli {

namespace {

struct DiagnoseArgs {
  std::string config;
  std::string csv;
  std::string db;
  std::string from;
  std::string to = "now";
  bool record = false;
  std::int64_t calibration_id = 0;
  std::int64_t run_at = 0;  // 0: now
  int parent_pid = 0;
  std::string variant;
  int train_days = 0;
  int heldout_days = 0;
  double step_s = 0.0;
  std::string report;
  std::vector<std::string> effects;
  double alpha = 0.05;
  double min_shrink_pct = 1.0;
  int threads = 0;
  std::string against_params;            // params.json of the plant before a change
  std::int64_t against_calibration = 0;  // with --db: that calibration's parameters
  std::string objective = "both";        // DiagnosisOptions::selection_outputs
};

// The diagnosis of a series (from a CSV or the store): runs, prints the
// summary on stdout, writes the report and leaves the result in *out.
int DiagnoseSeries(const Series& series, const Plant& plant, const ModelSpec& spec,
                   const DiagnosisOptions& options, const std::string& source,
                   const std::string& report_dir, DiagnosisResult* out) {
  DiagnosisResult& result = *out;
  std::string error;
  const bool ok = Diagnose(series, plant, spec, options, &result, &error,
                           [](const std::string& line) { std::cerr << line << "\n"; });
  if (!ok) {
    std::cerr << source << ": " << error << "\n";
    // Bad data (too little, missing columns) is bad input; a failed base fit is a runtime failure.
    return error.find("identification") != std::string::npos ? kExitRuntime : kExitBadInput;
  }
  std::printf("verdict: %s\n%s\n", result.verdict.c_str(), result.verdict_sentence.c_str());
  const GapBias bias = BaseModelBias(result);
  std::printf(
      "bias of the base model on the held-out days (predicted − measured): P_el %+.2f W "
      "(%.0f %% of its MAE), Q_u %+.2f W (%.0f %% of its MAE)\n\n",
      bias.p_el_w, 100 * bias.share_p_el, bias.q_th_w, 100 * bias.share_q_th);
  const double area_m2 = plant.area_m2;
  std::printf("ladder (held-out, MAE P_el + Q_u):\n");
  for (std::size_t k = 0; k < result.ladder.size(); ++k) {
    const LadderStep& s = result.ladder[k];
    std::printf(
        "  %-6s %-32s %s; P_el %s, Q_u %s%s\n", k == 0 ? "base" : ("+" + std::to_string(k)).c_str(),
        s.variant.c_str(), WattsAndPerM2(s.heldout_mae_w, area_m2).c_str(),
        WattsAndPerM2(s.heldout.mae_p_el_w, area_m2).c_str(),
        WattsAndPerM2(s.heldout.mae_q_th_w, area_m2).c_str(),
        k == 0 ? ""
               : ("  -" + std::to_string(static_cast<int>(s.shrink_pct + 0.5)) + " %").c_str());
  }
  std::printf("effects (ranked):\n");
  for (const EffectTrial& t : result.effects) {
    std::printf("  %-17s %s shrink %6.1f %%  better %zu/%zu %ss  loss test p = %.3g%s\n",
                t.name.c_str(), t.significant ? "SIGNIFICANT" : "           ", t.shrink_pct,
                t.test.positives, t.test.pairs, result.test_unit.c_str(), t.heldout_test.p,
                t.rejected.empty() ? "" : ("; not accepted: " + t.rejected).c_str());
  }
  for (const SensorFinding& f : result.sensors) {
    std::printf("sensor: %s %s on %zu rows (%.1f %%)%s: %s\n", f.channel.c_str(), f.kind.c_str(),
                f.rows, 100 * f.share,
                std::isfinite(f.size) ? (", size " + SensorSizeText(f)).c_str() : "",
                f.detail.c_str());
  }
  for (const Extrapolation& x : result.extrapolation) {
    std::printf(
        "extrapolated: %s held-out [%.3g, %.3g] vs training [%.3g, %.3g], %.0f %% of rows "
        "outside\n",
        x.driver.c_str(), x.heldout_low, x.heldout_high, x.train_low, x.train_high,
        100 * x.share_outside);
  }
  std::printf("where (regions of concentrated held-out error):\n");
  for (std::size_t k = 0; k < result.where.size() && k < 8; ++k) {
    const GapRegion& g = result.where[k];
    std::printf("  %-4s %-22s [%g, %g)%s%s  %4.1f %% of |error| in %4.1f %% of rows, z = %.1f\n",
                g.output.c_str(), g.driver.c_str(), g.lower, g.upper,
                g.label.empty() ? "" : (" " + g.label).c_str(),
                g.driver2.empty()
                    ? ""
                    : (" × " + g.driver2 + " [" + std::to_string(static_cast<int>(g.lower2)) +
                       ", " + std::to_string(static_cast<int>(g.upper2)) + ")")
                          .c_str(),
                100 * g.share_of_abs_error, 100 * g.share_of_rows, g.z);
  }
  std::printf("noise floor: P_el %s, Q_u %s; final held-out error = %.1f x floor\n",
              WattsAndPerM2(result.noise.mae_p_el_w, area_m2).c_str(),
              WattsAndPerM2(result.noise.mae_q_th_w, area_m2).c_str(), result.noise.ratio);
  for (const std::string& n : result.notes) std::printf("note: %s\n", n.c_str());
  std::fflush(stdout);
  if (!report_dir.empty()) {
    if (!WriteDiagnosisReport(report_dir, result, &error)) {
      std::cerr << error << "\n";
      return kExitRuntime;
    }
    std::cerr << "wrote " << report_dir << "/report.json and report.html\n";
  }
  return kExitOk;
}

// The diagnosis row of the store (Store::DiagnosisRow, doc/contracts.md).
bool RecordDiagnosis(Store& store, const DiagnosisResult& r, std::int64_t from_ts,
                     std::int64_t to_ts, const DiagnoseArgs& a) {
  Store::DiagnosisRow row;
  row.run_at = a.run_at > 0 ? a.run_at : static_cast<std::int64_t>(WallNowS());
  row.calibration_id = a.calibration_id;
  row.window_start = from_ts;
  row.window_end = to_ts;
  row.base_variant = r.base_variant;
  row.verdict = r.verdict;
  row.low_confidence = r.low_confidence;
  row.shrink_pct =
      r.ladder.size() > 1 && r.ladder.front().heldout_mae_w > 0.0
          ? 100.0 * (1.0 - r.ladder.back().heldout_mae_w / r.ladder.front().heldout_mae_w)
          : 0.0;
  const GapBias bias = BaseModelBias(r);
  row.bias_p_el_w = bias.p_el_w;
  row.bias_q_th_w = bias.q_th_w;
  row.report_json = DiagnosisReportJson(r);
  std::string error;
  if (!store.InsertDiagnosis(&row, &error)) {
    std::cerr << error << "\n";
    return false;
  }
  std::cerr << "recorded diagnosis " << row.id << " in " << store.path() << "\n";
  return true;
}

// The store's rows of [--from, --to) (default: the [calibration] window up
// to now): its 1-min rows, or without them its measurement_interval rows at
// their own step (daemon/service/window_data.h).
bool ReadStoreWindow(const DiagnoseArgs& a, const Config& config, std::unique_ptr<Store>* store,
                     WindowData* window, std::int64_t* from_out, std::int64_t* to_out) {
  std::int64_t& from_ts = *from_out;
  std::int64_t& to_ts = *to_out;
  if (!ParseTimeOrReport("--to", a.to, &to_ts)) return false;
  from_ts = to_ts - static_cast<std::int64_t>(config.calibration.window_days) * 86400;
  if (!a.from.empty() && !ParseTimeOrReport("--from", a.from, &from_ts)) return false;
  if (to_ts <= from_ts) {
    std::cerr << "--to = " << a.to << ": must be later than --from\n";
    return false;
  }
  if (!std::filesystem::exists(a.db)) {
    std::cerr << "--db = " << a.db << ": no such database\n";
    return false;
  }
  // Only --record writes (the daemon's nightly diagnosis); a reader's
  // diagnosis opens the store read-only and never migrates it.
  const bool opened = a.record ? OpenStoreOrReport(a.db, StoreOptionsFor(config), store)
                               : OpenStoreReadOnlyOrReport(a.db, StoreOptionsFor(config), store);
  if (!opened) return false;
  std::string error;
  if (!ReadWindowData(**store, from_ts, to_ts, window, &error)) {
    std::cerr << error << "\n";
    return false;
  }
  if (window->source == WindowSource::kNone) {
    std::cerr << "--db = " << a.db << ": no measurement_1min or measurement_interval rows in "
              << FormatIsoUtc(from_ts) << " .. " << FormatIsoUtc(to_ts) << "\n";
    return false;
  }
  if (window->source == WindowSource::kIntervals) {
    std::cerr << "--db = " << a.db << ": no 1-min rows in " << FormatIsoUtc(from_ts) << " .. "
              << FormatIsoUtc(to_ts) << "; diagnosing the " << window->rows.size() << " "
              << window->Describe() << " at their own step\n";
  }
  return true;
}

// The model step of a diagnosis of the store's window: --step, or the step of
// interval rows when --step is finer than they are or no multiple of theirs
// (the daemon passes its [calibration] step_s, made for 1-min rows). 0: the
// data's own.
double DiagnosisStep(const DiagnoseArgs& a, const WindowData& window) {
  if (window.source != WindowSource::kIntervals || a.step_s <= 0.0) return a.step_s;
  if (StepForData(a.step_s, window.rows.step_s) == a.step_s) return a.step_s;
  std::cerr << "--step = " << a.step_s << ": not a multiple of the interval rows' step; "
            << "diagnosing at their step of " << window.rows.step_s << " s\n";
  return 0.0;  // the data's own
}

// The monitor's sensor checks (core/monitor/monitoring.h) over interval rows,
// into qc_event: the daemon's daily checks look at the last two days only, so
// the faults of imported logger history are recorded here.
bool RecordIntervalSensorFaults(Store& store, const Series& rows, const Plant& plant) {
  const std::vector<SensorFault> faults = FindSensorFaults(rows, plant);
  std::string error;
  if (!store.RecordSensorFaults(faults, &error)) {
    std::cerr << error << "\n";
    return false;
  }
  std::cerr << "recorded " << faults.size() << " sensor fault(s) of the interval rows in qc_event"
            << "\n";
  return true;
}

// --against-params or --against-calibration: the base model keeps the
// parameters of the plant before a change (DiagnosisOptions::reference_params).
bool AgainstModelBefore(const DiagnoseArgs& a, const Plant& plant, const ModelSpec& spec,
                        Store* store, DiagnosisOptions* options) {
  if (a.against_params.empty() && a.against_calibration == 0) return true;
  if (!a.against_params.empty() && a.against_calibration != 0) {
    std::cerr << "--against-params, --against-calibration: give one of them\n";
    return false;
  }
  ParamsFile file;
  file.values = StartParams(plant);
  Diagnostics errors;
  std::string name = a.against_params;
  if (!a.against_params.empty()) {
    if (!ReadParamsJson(a.against_params, plant, &file, &errors)) {
      for (const Diagnostic& d : errors) std::cerr << d.ToString() << "\n";
      return false;
    }
  } else {
    if (store == nullptr) {
      std::cerr << "--against-calibration: only with --db (the calibration of that store)\n";
      return false;
    }
    Store::CalibrationRow row;
    bool found = false;
    std::string error;
    if (!store->AcceptedCalibrationById(a.against_calibration, &row, &found, &error)) {
      std::cerr << error << "\n";
      return false;
    }
    if (!found) {
      std::cerr << "--against-calibration = " << a.against_calibration
                << ": no accepted calibration with that id in " << a.db << "\n";
      return false;
    }
    name = "calibration " + std::to_string(row.id) + " (window " + FormatIsoUtc(row.window_start) +
           " to " + FormatIsoUtc(row.window_end) + ")";
    if (!ParseParamsJson(row.params_json, name, plant, &file, &errors)) {
      for (const Diagnostic& d : errors) std::cerr << d.ToString() << "\n";
      return false;
    }
    file.variant = row.variant;
    // The days it was fitted on: each candidate's gain is judged beyond
    // what it gains with its own parameters as fitted there
    // (DiagnosisOptions::reference_days).
    WindowData days;
    if (!ReadWindowData(*store, row.window_start, row.window_end, &days, &error)) {
      std::cerr << error << "\n";
      return false;
    }
    if (days.rows.size() >= 2) {
      options->reference_days = std::make_shared<const Series>(std::move(days.rows));
    } else {
      std::cerr << name << ": no rows of its window left in " << a.db
                << "; each candidate is judged against the model without it\n";
    }
  }
  if (!file.variant.empty() && file.variant != spec.Name()) {
    std::cerr << name << ": parameters of " << file.variant
              << ", but the diagnosis's base model is " << spec.Name() << " (--variant)\n";
    return false;
  }
  options->reference_params = file.values;
  options->reference_name = name;
  return true;
}

int RunDiagnose(const DiagnoseArgs& a) {
  if (!DieWithParent(a.parent_pid)) return kExitRuntime;
  if (a.csv.empty() == a.db.empty()) {
    std::cerr << "diagnose: give either --csv (a canonical CSV) or --db (the store's "
                 "measurement_1min or measurement_interval)\n";
    return kExitBadInput;
  }
  if (a.record && a.db.empty()) {
    std::cerr << "--record: only with --db (the diagnosis row goes to that store)\n";
    return kExitBadInput;
  }
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  const std::string variant =
      a.variant.empty() && !a.db.empty() ? config.calibration.variant : a.variant;
  if (variant.empty()) {
    std::cerr << "--variant: required with --csv (with --db the default is [calibration] "
                 "variant)\n";
    return kExitBadInput;
  }
  ModelSpec spec;
  if (!ParseVariantOrReport(variant, &spec)) return kExitBadInput;
  DiagnosisOptions options;
  options.train_days = a.train_days;
  options.heldout_days = a.heldout_days;
  options.step_s = a.step_s;
  options.effects = a.effects;
  options.alpha = a.alpha;
  options.min_shrink_pct = a.min_shrink_pct;
  options.threads = a.threads;
  ParseSelectionOutputs(a.objective, &options.selection_outputs);  // checked by the parser
  std::string why;
  if (!options.IsValid(&why)) {
    std::cerr << "diagnose: " << why << "\n";
    return kExitBadInput;
  }
  WindowData window;
  Series& series = window.rows;
  std::unique_ptr<Store> store;
  std::int64_t from_ts = 0, to_ts = 0;
  if (!a.db.empty()) {
    if (!ReadStoreWindow(a, config, &store, &window, &from_ts, &to_ts)) return kExitBadInput;
    options.step_s = DiagnosisStep(a, window);
    // The sensor checks do not need the model: recorded even when the
    // diagnosis cannot run.
    if (a.record && window.source == WindowSource::kIntervals &&
        !RecordIntervalSensorFaults(*store, series, config.plant)) {
      return kExitRuntime;
    }
  } else if (!LoadCsvOrReport(a.csv, config, &series)) {
    return kExitBadInput;
  }
  const std::string source = a.db.empty() ? a.csv : a.db;
  if (!AgainstModelBefore(a, config.plant, spec, store.get(), &options)) return kExitBadInput;
  Drivers drivers;
  if (!PrepareDriversOrReport(series, source, config, spec, &drivers)) return kExitBadInput;
  DiagnosisResult result;
  const int rc = DiagnoseSeries(series, config.plant, spec, options, source, a.report, &result);
  if (rc != kExitOk || !a.record) return rc;
  // The residual sensor checks' faults (with their onset) go to qc_event
  // beside the diagnosis row, seen until the end of the window.
  const std::vector<SensorFault> diagnosed = DiagnosedSensorFaults(result, to_ts);
  std::string qc_error;
  if (!store->RecordSensorFaults(diagnosed, &qc_error)) {
    std::cerr << qc_error << "\n";
    return kExitRuntime;
  }
  if (!diagnosed.empty()) {
    std::cerr << "recorded " << diagnosed.size() << " diagnosed sensor fault(s) in qc_event\n";
  }
  return RecordDiagnosis(*store, result, from_ts, to_ts, a) ? kExitOk : kExitRuntime;
}

struct SelftestArgs {
  int seeds = 1;
  int days = 21;
  int heldout_days = 7;
  double step_s = 60;
  int jobs = 0;
  std::uint64_t first_seed = 1;
  std::vector<std::string> cases;
  std::string report;
  std::string battery = "both";
};

// The cases of the batteries `battery` asks for (same, other, both), same-form
// first.
std::vector<SelftestCase> BatteryCases(const Plant& plant, const std::string& battery) {
  std::vector<SelftestCase> cases;
  if (battery != "other") cases = SelftestCases(plant);
  if (battery != "same") {
    for (SelftestCase& c : OtherFormSelftestCases(plant)) cases.push_back(std::move(c));
  }
  return cases;
}

// Whether every battery in outcomes meets the target: >= 90 % correct and no
// false significant effect on a null case.
bool SelftestPasses(const std::vector<SelftestOutcome>& outcomes) {
  bool pass = !outcomes.empty();
  for (TruthForm form : {TruthForm::kSameForm, TruthForm::kOtherForm}) {
    int n = 0, correct = 0, false_sig = 0;
    for (const SelftestOutcome& o : outcomes) {
      if (o.form != form) continue;
      ++n;
      correct += o.correct;
      false_sig += o.false_significant;
    }
    if (n == 0) continue;
    const bool ok = correct >= 0.9 * static_cast<double>(n) && false_sig == 0;
    std::printf(
        "%s (%s battery): target >= 90 %% correct and no false significant effect on "
        "null cases\n",
        ok ? "PASS" : "FAIL", std::string(TruthFormName(form)).c_str());
    pass = pass && ok;
  }
  return pass;
}

int RunSelftest(const SelftestArgs& a) {
  const Plant plant = DesignExamplePlant();
  SelftestOptions options;
  options.heldout_days = a.heldout_days;
  options.train_days = a.days - a.heldout_days;
  options.step_s = a.step_s;
  options.seeds = a.seeds;
  options.first_seed = a.first_seed;
  options.diagnosis.threads = 1;  // parallel over cases instead
  if (options.train_days < 1) {
    std::cerr << "--days = " << a.days << ": must exceed --heldout-days = " << a.heldout_days
              << "\n";
    return kExitBadInput;
  }
  if (a.battery != "same" && a.battery != "other" && a.battery != "both") {
    std::cerr << "--battery = " << a.battery << ": must be same, other or both\n";
    return kExitBadInput;
  }
  std::vector<SelftestCase> cases = BatteryCases(plant, a.battery);
  if (!a.cases.empty()) {
    std::vector<SelftestCase> chosen;
    for (const std::string& name : a.cases) {
      bool found = false;
      for (const SelftestCase& c : cases) {
        if (c.name == name) {
          chosen.push_back(c);
          found = true;
        }
      }
      if (!found) {
        std::cerr << "--cases = " << name << ": no such case (";
        for (std::size_t k = 0; k < cases.size(); ++k)
          std::cerr << (k ? ", " : "") << cases[k].name;
        std::cerr << ")\n";
        return kExitBadInput;
      }
    }
    cases = chosen;
  }
  // An other-form case whose data equal its same-form twin's (null,
  // disturbances) reuses the twin's outcome when both batteries run.
  struct Job {
    const SelftestCase* c;
    std::uint64_t seed;
    std::ptrdiff_t twin = -1;  // job whose outcome this one copies
  };
  std::vector<Job> jobs;
  for (int s = 0; s < a.seeds; ++s) {
    const std::size_t first_of_seed = jobs.size();
    for (const SelftestCase& c : cases) {
      Job job{&c, a.first_seed + static_cast<std::uint64_t>(s)};
      for (std::size_t k = first_of_seed;
           k < jobs.size() && c.form == TruthForm::kOtherForm && !OtherFormChangesData(c); ++k) {
        if (jobs[k].c->name == c.name && jobs[k].c->form == TruthForm::kSameForm) {
          job.twin = static_cast<std::ptrdiff_t>(k);
        }
      }
      jobs.push_back(job);
    }
  }
  std::vector<SelftestOutcome> outcomes(jobs.size());
  std::atomic<std::size_t> next{0};
  std::atomic<int> done{0};
  std::mutex mutex;
  std::size_t to_run = 0;
  for (const Job& job : jobs) to_run += job.twin < 0;
  auto worker = [&] {
    for (std::size_t k = next++; k < jobs.size(); k = next++) {
      if (jobs[k].twin >= 0) continue;
      std::string log;
      auto keep_log = [&log](const std::string& line) { log += line + "\n"; };
      outcomes[k] = a.report.empty()
                        ? RunSelftestCase(plant, *jobs[k].c, jobs[k].seed, options)
                        : RunSelftestCase(plant, *jobs[k].c, jobs[k].seed, options, keep_log);
      outcomes[k].log = std::move(log);
      const SelftestOutcome& o = outcomes[k];
      std::lock_guard<std::mutex> lock(mutex);
      std::fprintf(stderr, "[%d/%zu] %s %s seed %llu: verdict %s (expected %s) %s %.1f s\n", ++done,
                   to_run, std::string(TruthFormName(o.form)).c_str(), o.case_name.c_str(),
                   static_cast<unsigned long long>(o.seed), o.verdict.c_str(), o.expected.c_str(),
                   o.correct ? "ok" : ("WRONG: " + o.why).c_str(), o.wall_time_s);
    }
  };
  const int n_threads =
      a.jobs > 0 ? a.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  {
    std::vector<std::thread> pool;
    for (int w = 1; w < n_threads; ++w) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
  }
  std::printf("diagnosis self-test: %d train + %d held-out days at %g s, %d seed(s) from %llu\n\n",
              options.train_days, options.heldout_days, options.step_s, a.seeds,
              static_cast<unsigned long long>(a.first_seed));
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    if (jobs[k].twin < 0) continue;
    outcomes[k] = outcomes[static_cast<std::size_t>(jobs[k].twin)];
    outcomes[k].form = TruthForm::kOtherForm;
  }
  std::printf("%s", FormatSelftestBatteries(outcomes).c_str());
  if (!a.report.empty()) {
    for (const SelftestOutcome& o : outcomes) {
      std::string error;
      const std::string dir = a.report + "/" +
                              (o.form == TruthForm::kOtherForm ? "other-form-" : "") + o.case_name +
                              "-seed" + std::to_string(o.seed);
      if (o.verdict != "error" && !WriteDiagnosisReport(dir, o.result, &error)) {
        std::cerr << error << "\n";
        return kExitRuntime;
      }
      if (o.verdict != "error" && !WriteTextFileAtomically(dir + "/diagnosis.log", o.log, &error)) {
        std::cerr << error << "\n";
        return kExitRuntime;
      }
    }
  }
  return SelftestPasses(outcomes) ? kExitOk : kExitRuntime;
}

}  // namespace

void RegisterDiagnose(CLI::App& app) {
  auto args = std::make_shared<DiagnoseArgs>();
  CLI::App* cmd = app.add_subcommand(
      "diagnose",
      "Sim-to-real gap diagnosis. Identifies the variant on the first training days, predicts\n"
      "the held-out days after them, and reports: where the held-out error concentrates (by\n"
      "hour, day, angle of incidence, irradiance and its rate of change, beam fraction, wind,\n"
      "sky temperature deficit, T_in - T_amb, flow, pump switching, sun position); which\n"
      "catalogued effect (capacitance, second_node, wind, sky_radiation, iam, ...) removes it,\n"
      "tested by adding the effect, re-identifying and scoring the held-out days: the held-out\n"
      "days are resampled, and an effect's confidence is the share of resamples in which it is\n"
      "the best candidate and beats the model (over hours when there are fewer than 5 held-out\n"
      "days, reported as low confidence); the ladder of accepted effects; and a verdict: an\n"
      "effect (confidence >= 0.8), 'undecided' (the top two named), 'none' (error near the\n"
      "sensor-noise floor) or 'unknown' (error far above noise that no effect removes).\n"
      "Progress on stderr, a summary on stdout, DIR/report.json (doc/contracts.md) and "
      "DIR/report.html\n"
      "with --report. Exit 0 success, 2 bad input, 1 the base fit failed or the report could\n"
      "not be written.");
  cmd->add_option("--config", args->config, "TOML config with the [plant] section")->required();
  cmd->add_option("--csv", args->csv, "canonical CSV with the measurements");
  cmd->add_option("--db", args->db,
                  "instead of --csv: the measurement_1min rows of this SQLite store, or its "
                  "measurement_interval rows at their own step when the window has no 1-min "
                  "rows");
  cmd->add_option("--from", args->from,
                  "with --db: first time, ISO 8601, a date or relative such as -14d (default: "
                  "--to minus [calibration] window_days)");
  cmd->add_option("--to", args->to, "with --db: end time, exclusive (default: now)");
  cmd->add_flag("--record", args->record,
                "with --db: write the result as a row of the store's diagnosis table (and, "
                "for measurement_interval rows, their sensor faults to qc_event)");
  cmd->add_option("--calibration-id", args->calibration_id,
                  "with --record: the calibration whose window is diagnosed");
  cmd->add_option("--run-at", args->run_at,
                  "with --record: the row's run_at, unix s (default: now; pvtwin run passes its "
                  "clock)")
      ->group("");
  cmd->add_option("--parent-pid", args->parent_pid,
                  "exit when the process with this pid ends (used by pvtwin run)")
      ->group("");
  cmd->add_option("--variant", args->variant,
                  "base model variant, e.g. 1N1Cwr (required with --csv; with --db the default is "
                  "[calibration] variant)");
  cmd->add_option("--train-days", args->train_days,
                  "training days from the first day of data (default: two thirds of the days; "
                  "with --against-params or --against-calibration, each day is held out in "
                  "turn, its effects fitted on the other days)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("auto");
  cmd->add_option("--heldout-days", args->heldout_days,
                  "held-out days after the training days (default: all remaining)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("auto");
  cmd->add_option("--step", args->step_s,
                  "average the data to this step in s before diagnosing (default: the data's)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("auto");
  cmd->add_option("--effects", args->effects,
                  "comma-separated effects to test (default: every one the model can take)")
      ->delimiter(',');
  cmd->add_option("--alpha", args->alpha,
                  "p at or below which a sensor test (a pyranometer's scale error) names a fault; "
                  "the effects are chosen by their bootstrap confidence (0.05)");
  cmd->add_option("--min-shrink", args->min_shrink_pct,
                  "smallest held-out error reduction in % that counts (1)");
  cmd->add_option("--threads", args->threads, "worker threads, 0 = all cores (default 0)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--report", args->report, "directory for report.json and report.html");
  cmd->add_option("--against-params", args->against_params,
                  "params.json of the plant before a change (as calibrate --out writes it): the "
                  "base model keeps these parameters, and each effect fits only its own, so the "
                  "verdict says which effect explains what changed; only effects that can begin "
                  "while the plant runs are tried (default: fit the base on the training days)");
  cmd->add_option("--against-calibration", args->against_calibration,
                  "with --db: as --against-params, with the parameters of this accepted "
                  "calibration of the store (pvtwin run passes the one before a performance "
                  "alarm's change); each effect's own parameters are also fitted on the days "
                  "of its window, and an effect counts only with its gain beyond what it gains "
                  "with them")
      ->check(CLI::PositiveNumber)
      ->default_str("none");
  cmd->add_option("--objective", args->objective,
                  "the outputs whose held-out MAE the model selection compares: both (the "
                  "paper's objective), or the one whose change is diagnosed, p_el or q_th, at "
                  "the first ladder step, both at later ones (pvtwin run passes the output "
                  "whose performance alarm dated the change)")
      ->check(CLI::IsMember({"both", "p_el", "q_th"}))
      ->capture_default_str();
  cmd->callback([args] { SetExitCode(RunDiagnose(*args)); });

  auto st = std::make_shared<SelftestArgs>();
  CLI::App* self = app.add_subcommand(
      "diagnose-selftest",
      "Proof of the diagnosis on synthetic data with a known answer: for each effect of the\n"
      "catalogue, data from a truth model that has it (realistic weather, pump hysteresis,\n"
      "sensor noise, the paper's data defects) are diagnosed with a base model that lacks it;\n"
      "plus a null case (nothing withheld: expect 'none') and two uncatalogued disturbances\n"
      "(a failing pump, snow cover on two held-out days: expect 'unknown' with 'where' on those\n"
      "days). Two batteries: the same-form one (truth from the candidates' own equations) and\n"
      "the other-form one (each effect implemented in another functional form than the\n"
      "candidate meant to find it). Prints each case, a confusion table and the hit rate per\n"
      "battery. Exit 0 when in every battery run >= 90 % are correct and no null case has a\n"
      "significant effect, else 1.");
  self->add_option("--seeds", st->seeds, "seeds per case (default 1)")->check(CLI::PositiveNumber);
  self->add_option("--first-seed", st->first_seed, "first seed (default 1)");
  self->add_option("--days", st->days, "days of data per case, training + held-out (default 21)")
      ->check(CLI::PositiveNumber);
  self->add_option("--heldout-days", st->heldout_days, "held-out days (default 7)")
      ->check(CLI::Range(2, 60));
  self->add_option("--step", st->step_s, "data step in s (default 60)")
      ->check(CLI::Range(5.0, 900.0));
  self->add_option("--jobs", st->jobs, "cases run in parallel, 0 = all cores (default 0)")
      ->check(CLI::NonNegativeNumber);
  self->add_option("--cases", st->cases, "comma-separated case names (default: all)")
      ->delimiter(',');
  self->add_option("--report", st->report,
                   "write each case's report and its diagnosis.log to DIR/<case>-seed<N>/ "
                   "(other-form battery: DIR/other-form-<case>-seed<N>/)");
  self->add_option("--battery", st->battery,
                   "same: truth from the candidates' own equations; other: each effect in "
                   "another functional form than its candidate (a horizon profile on some "
                   "days for the obstacle box, a soft inverter knee for the hard clip, ...); "
                   "both (default): both tables");
  self->callback([st] { SetExitCode(RunSelftest(*st)); });
}

}  // namespace pvtwin::cli
