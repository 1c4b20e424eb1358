// pvtwin calibrate: identify a variant's parameters from operation data.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "core/common/heap.h"
#include "core/data/resample.h"
#include "core/fit/identification.h"
#include "core/fit/iso9806.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/calibration_fit.h"
#include "io/files/params_json.h"
#include "io/platform/quantity_text.h"
#include "io/platform/time_format.h"

namespace pvtwin::cli {

namespace {

struct CalibrateArgs {
  std::string config;
  std::string csv;
  std::string variant;
  std::string out;
  std::string train_start;
  std::string train_end;
  std::string start_params;
  std::string test_csv;
  std::string algorithm = "lad_lm";
  std::string jacobian;  // "", "differences" or "sensitivities"
  std::vector<std::string> free;
  std::vector<std::string> fix;
  double step_s = 0.0;
  int max_evaluations = 0;
  double ftol_rel = 0.0;
  bool use_t_pv = false;
  bool timing = false;
  int parent_pid = 0;
  int threads = 0;  // 0: two when the machine has them
};

// Wall time of the stages of one calibrate run, for --timing.
struct StageTimes {
  std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
  double parse_s = 0.0;    // reading the CSVs
  double prepare_s = 0.0;  // window, resampling, drivers, measurements
  double held_out_s = 0.0;
  double write_s = 0.0;

  // Seconds since the previous call.
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last).count();
    last = now;
    return s;
  }
};

// One line on standard error: parse / prepare / fit (coarse, fine) /
// held-out / write, in ms, and the model runs of each fit stage (as
// counted against the budget; those served from an earlier run's outputs
// took no time).
void PrintTiming(const StageTimes& t, const IdentSummary& s) {
  const std::string subset_text = s.CoarseSubsetText();
  const std::string subset = subset_text.empty() ? "" : ", " + subset_text;
  std::fprintf(stderr,
               "timing: parse %.1f ms, prepare %.1f ms, fit %.1f ms (coarse %.1f ms, %d model "
               "runs%s; fine %.1f ms, %d model runs, of which identifiability (standard "
               "errors, fixing rounds) %.1f ms, %d model runs, %d of them on the coarse data, "
               "trial fits %.1f ms), held-out %.1f ms, write %.1f ms; %d of the model runs with "
               "sensitivities (each counted as %d); %d counted but served from an earlier run\n",
               1e3 * t.parse_s, 1e3 * t.prepare_s, 1e3 * s.runtime_s, 1e3 * s.coarse_runtime_s,
               s.coarse_evaluations, subset.c_str(), 1e3 * (s.runtime_s - s.coarse_runtime_s),
               s.evaluations - s.coarse_evaluations, 1e3 * s.fixing_runtime_s, s.fixing_evaluations,
               s.fixing_coarse_evaluations, 1e3 * s.trial_runtime_s, 1e3 * t.held_out_s,
               1e3 * t.write_s, s.sensitivity_runs, kSensitivityRunCost, s.served_runs);
}

bool ResampleOrReport(const std::string& path, double step_s, Series* s) {
  if (step_s <= 0.0 || step_s == s->step_s) return true;
  Series out;
  std::string error;
  if (!Resample(*s, step_s, &out, &error)) {
    std::cerr << "--step = " << step_s << ": " << path << ": " << error << "\n";
    return false;
  }
  *s = std::move(out);
  return true;
}

std::string Percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f %%", 100.0 * fraction);
  return std::isfinite(fraction) ? buf : "n/a";
}

void PrintErrors(const char* label, const ErrorMetrics& e, double area_m2) {
  std::printf("%-26s MAE P_el %s, nMAE %s; MAE Q_u %s, nMAE %s; %zu rows\n", label,
              WattsAndPerM2(e.mae_p_el_w, area_m2).c_str(), Percent(e.nmae_p_el).c_str(),
              WattsAndPerM2(e.mae_q_th_w, area_m2).c_str(), Percent(e.nmae_q_th).c_str(), e.rows);
}

std::string StatusOf(const ParamEstimate& e) {
  if (!e.free) return "fixed";
  if (e.undetermined) return "fixed: not determined by the data";
  if (e.at_bound)
    return e.value - e.lower < e.upper - e.value ? "at lower bound" : "at upper bound";
  return e.weak ? "weakly determined" : "identified";
}

// "± 0.123", empty when StdError is NaN.
std::string PlusMinus(const ParamEstimate& e) {
  const double se = StdErrorInUnit(e);
  if (std::isnan(se)) return "";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "± %.3g", se);
  return buf;
}

// What the report after the fit reads of the training series, taken
// before the fit so that the series can be released (RunCalibrate).
struct TrainingWindow {
  std::size_t rows = 0;
  std::int64_t first_s = 0, last_s = 0;
  double step_s = 0.0;
  // The median flow of the rows with flow, NaN without any: the flow of the
  // ISO 9806 equivalents.
  double median_flow_kg_s = std::nan("");
};

TrainingWindow WindowOf(const Series& train) {
  TrainingWindow w;
  w.rows = train.size();
  if (!train.time_s.empty()) {
    w.first_s = train.time_s.front();
    w.last_s = train.time_s.back();
  }
  w.step_s = train.step_s;
  std::vector<double> flows;
  for (const double f : train[Channel::kMdotKgS]) {
    if (f > 1e-4) flows.push_back(f);
  }
  if (!flows.empty()) {
    std::nth_element(flows.begin(), flows.begin() + static_cast<std::ptrdiff_t>(flows.size() / 2),
                     flows.end());
    w.median_flow_kg_s = flows[flows.size() / 2];
  }
  return w;
}

// The ISO 9806 quasi-dynamic coefficients of the fit, for a datasheet, at
// the training data's median flow (none without flow).
void PrintIsoEquivalents(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                         double flow_kg_s) {
  if (std::isnan(flow_kg_s)) return;
  const Iso9806Equivalents iso = Iso9806EquivalentsOf(plant, spec, params, flow_kg_s);
  if (!iso.ok) return;
  std::printf(
      "ISO 9806 equivalents (steady state, 1000 W/m2 beam at normal incidence, ambient 25 C, "
      "flow %.3g kg/s, wind %.1f m/s): eta0 %.3f, c1 + c3*u %.2f W/(m2K); slopes c3 %.2f "
      "J/(m3K), c6 %.4f s/m; c4 %.3f; heat capacity %.0f J/(m2K)\n",
      flow_kg_s, iso.u_ref_m_s, iso.eta0, iso.loss_w_m2k, iso.c3_j_m3k, iso.c6_s_m, iso.c4,
      iso.c5_j_m2k);
}

// The "fit" object of params.json (daemon/service/calibration_fit.h): the
// fit's summary and every parameter as the table prints it (the daemon
// stores them in calibration_param).
CalibrationFit FitOf(const IdentSummary& s, const ErrorMetrics* held_out) {
  CalibrationFit fit;
  fit.algorithm = s.algorithm;
  fit.termination = std::string(ToString(s.termination));
  fit.initial_cost_w_m2 = s.initial_cost_w_m2;
  fit.final_cost_w_m2 = s.final_cost_w_m2;
  fit.simulations = s.evaluations;
  fit.runtime_s = s.runtime_s;
  fit.train = s.train;
  if (held_out) fit.held_out = *held_out;
  fit.at_bounds = s.AtBounds();
  for (const ParamEstimate& e : s.estimates) {
    fit.parameters.push_back({std::string(Info(e.param).name), e.value, StdErrorInUnit(e),
                              std::string(Info(e.param).unit), StatusOf(e)});
    if (e.undetermined) fit.undetermined.push_back(std::string(Info(e.param).name));
  }
  return fit;
}

bool ParamSetOrReport(const std::string& option, const std::vector<std::string>& names,
                      std::bitset<kNumParams>* set) {
  bool ok = true;
  for (const std::string& n : names) {
    const std::optional<Param> p = ParamFromName(n);
    if (!p) {
      std::cerr << option << " = " << n << ": unknown parameter (see params.h or params.json)\n";
      ok = false;
      continue;
    }
    set->set(static_cast<std::size_t>(*p));
  }
  return ok;
}

// The heap a calibration takes at once: a fixed part and a part per byte
// of its CSV files (UseHugePageHeap).
constexpr std::uintmax_t kHeapBytesFixed = std::uintmax_t{16} << 20;
constexpr std::uintmax_t kHeapBytesPerCsvByte = 4;
constexpr std::uintmax_t kHeapBytesMax = std::uintmax_t{4} << 30;

// The size of the file at `path`; 0 for none or when it cannot be read.
std::uintmax_t FileBytes(const std::string& path) {
  if (path.empty()) return 0;
  std::error_code error;
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  return error ? 0 : bytes;
}

// The held-out data of --test-csv: its drivers and measurements, the series
// released as the training one is (RunCalibrate). False after reporting a
// bad file.
bool LoadHeldOutOrReport(const CalibrateArgs& a, const Config& config, const ModelSpec& spec,
                         StageTimes* times, Drivers* drivers, Measurements* meas) {
  Series test;
  if (!LoadCsvOrReport(a.test_csv, config, &test)) return false;
  times->parse_s += times->Lap();
  if (!ResampleOrReport(a.test_csv, a.step_s, &test)) return false;
  if (!PrepareDriversOrReport(test, a.test_csv, config, spec, drivers)) return false;
  *meas = MakeMeasurements(test, *drivers);
  times->prepare_s += times->Lap();
  return true;
}

int RunCalibrate(const CalibrateArgs& a) {
  if (!DieWithParent(a.parent_pid)) return kExitRuntime;
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  ModelSpec spec;
  if (!ParseVariantOrReport(a.variant, &spec)) return kExitBadInput;
  IdentOptions options;
  if (!SetIdentAlgorithm(a.algorithm, &options)) {
    std::cerr << "--algorithm = " << a.algorithm
              << ": unknown (lad_lm, bobyqa, sbplx, nelder_mead, cobyla, lbfgs, mma, crs2_bobyqa, "
                 "multistart_bobyqa, mlsl_bobyqa)\n";
    return kExitBadInput;
  }
  if (!a.jacobian.empty()) options.analytic_jacobian = a.jacobian == "sensitivities";
  if (a.max_evaluations > 0) options.optimizer.max_evaluations = a.max_evaluations;
  if (a.ftol_rel > 0.0) options.optimizer.ftol_rel = a.ftol_rel;
  options.use_t_pv = a.use_t_pv;
  options.threads = a.threads > 0 ? a.threads : std::thread::hardware_concurrency() >= 2 ? 2 : 1;
  std::bitset<kNumParams> free_set, fix_set;
  if (!ParamSetOrReport("--free", a.free, &free_set) ||
      !ParamSetOrReport("--fix", a.fix, &fix_set)) {
    return kExitBadInput;
  }
  options.free = (free_set.any() ? free_set : DefaultFreeParams(spec)) & ~fix_set;
  if (options.free.none()) options.free = DefaultFreeParams(spec) & ~fix_set;

  ParamVector start = StartParams(config.plant);
  if (!a.start_params.empty()) {
    ParamsFile file;
    Diagnostics errors;
    if (!ReadParamsJson(a.start_params, config.plant, &file, &errors)) {
      for (const Diagnostic& d : errors) std::cerr << d.ToString() << "\n";
      return kExitBadInput;
    }
    start = file.values;
    // Most often the last calibration: the day subset stage's fit would
    // only move away from it (IdentOptions::day_subset_stage).
    options.day_subset_stage = false;
  }

  // The working set is written once (see heap.h): some 2.6 times the CSV's
  // bytes at 1 min and at 5 s; room for more is cheap, as only the pages
  // written are backed.
  UseHugePageHeap(static_cast<std::size_t>(std::min(
      kHeapBytesMax,
      kHeapBytesFixed + kHeapBytesPerCsvByte * (FileBytes(a.csv) + FileBytes(a.test_csv)))));
  StageTimes times;
  Series series;
  if (!LoadCsvOrReport(a.csv, config, &series)) return kExitBadInput;
  times.parse_s += times.Lap();
  std::int64_t t_begin = series.time_s.empty() ? 0 : series.time_s.front();
  std::int64_t t_end = series.time_s.empty() ? 0 : series.time_s.back() + 1;
  if (!a.train_start.empty() && !ParseTimeOrReport("--train-start", a.train_start, &t_begin)) {
    return kExitBadInput;
  }
  if (!a.train_end.empty() && !ParseTimeOrReport("--train-end", a.train_end, &t_end)) {
    return kExitBadInput;
  }
  // The whole file is the usual window: moved, not copied.
  const bool whole =
      series.size() == 0 || (t_begin <= series.time_s.front() && t_end > series.time_s.back());
  Series train = whole ? std::move(series) : series.Between(t_begin, t_end);
  if (!ResampleOrReport(a.csv, a.step_s, &train)) return kExitBadInput;
  Drivers drivers;
  if (!PrepareDriversOrReport(train, a.csv, config, spec, &drivers)) return kExitBadInput;
  const Measurements meas = MakeMeasurements(train, drivers);
  // The fit reads the drivers and the measurements only: the series is
  // released, and its columns (some 30 MB for 14 days at 5 s) are the room
  // the held-out data and the fit's Jacobians are carved from, where fresh
  // pages would each have to be faulted in and cleared (UseHugePageHeap
  // keeps freed memory; doc/performance.md).
  const TrainingWindow window = WindowOf(train);
  train = Series{};
  series = Series{};
  times.prepare_s += times.Lap();
  if (static_cast<int>(meas.rows.size()) < options.min_rows) {
    std::cerr << a.csv << ": training window " << FormatIsoUtc(t_begin) << " .. "
              << FormatIsoUtc(t_end) << " has " << meas.rows.size()
              << " usable rows (valid, with flow, irradiance, p_el_w and q_th_w or t_out_c); at "
                 "least "
              << options.min_rows << " are needed\n";
    return kExitBadInput;
  }

  // Held-out data, checked before the (long) fit.
  Drivers test_drivers;
  Measurements test_meas;
  if (!a.test_csv.empty() &&
      !LoadHeldOutOrReport(a, config, spec, &times, &test_drivers, &test_meas)) {
    return kExitBadInput;
  }

  std::fprintf(stderr, "calibrating %s on %zu rows (%zu in the objective) of %s ...\n",
               spec.Name().c_str(), window.rows, meas.rows.size(), a.csv.c_str());
  times.Lap();
  const IdentSummary summary = Identify(drivers, meas, start, options);
  times.Lap();
  std::printf("%s\n", summary.BriefReport().c_str());
  std::printf("training data: %s, %s .. %s, step %.0f s\n", a.csv.c_str(),
              FormatIsoUtc(window.first_s).c_str(), FormatIsoUtc(window.last_s).c_str(),
              window.step_s);
  PrintErrors("errors (training):", summary.train, config.plant.area_m2);
  ErrorMetrics held_out;
  if (!a.test_csv.empty()) {
    SimOutputs sim;
    Simulate(test_drivers, summary.params, &sim);
    held_out = ComputeErrors(test_meas, sim, config.plant.area_m2);
    PrintErrors("errors (held out):", held_out, config.plant.area_m2);
    times.held_out_s = times.Lap();
  }
  std::printf("parameters:\n  %-22s %12s %-11s %-16s %12s  %-22s %s\n", "name", "value",
              "std. error", "unit", "start", "range", "status");
  for (const ParamEstimate& e : summary.estimates) {
    const ParamInfo& info = Info(e.param);
    char range[48];
    std::snprintf(range, sizeof(range), "[%.3g, %.3g]", e.lower, e.upper);
    std::printf("  %-22s %12.5g %-11s %-16s %12.5g  %-22s %s\n", std::string(info.name).c_str(),
                e.value, PlusMinus(e).c_str(), std::string(info.unit).c_str(), e.start, range,
                StatusOf(e).c_str());
  }
  if (summary.ok) PrintIsoEquivalents(config.plant, spec, summary.params, window.median_flow_kg_s);
  for (const std::string& note : summary.notes) std::printf("note: %s\n", note.c_str());
  if (!summary.ok) {
    if (a.timing) PrintTiming(times, summary);
    std::fprintf(stderr, "calibration failed: %s\n", summary.failure_reason.c_str());
    return kExitRuntime;
  }
  times.Lap();
  if (!a.out.empty()) {
    std::string error;
    const std::string text =
        FormatParamsJson(spec.Name(), summary.params, UsedParams(spec),
                         FitOf(summary, a.test_csv.empty() ? nullptr : &held_out).ToJson());
    if (!WriteTextFileAtomically(a.out, text, &error)) {
      std::cerr << error << "\n";
      return kExitRuntime;
    }
    times.write_s = times.Lap();
    std::fprintf(stderr, "wrote %s\n", a.out.c_str());
  }
  if (a.timing) PrintTiming(times, summary);
  return kExitOk;
}

}  // namespace

void RegisterCalibrate(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Identify the parameters of a model variant from operation data (paper 3.2): minimise\n"
      "MAE(P_el) + MAE(Q_u) per m2 over the valid rows with flow, irradiance and outputs.\n"
      "Prints the fit, the errors and each parameter with its status (identified, at a bound,\n"
      "fixed because the data do not determine it); writes params.json for `pvtwin simulate`.\n"
      "Exit code 1 when the fit fails (the reason is printed and no file is written).");
  cmd->add_option("--config", args->config, "TOML config with the [plant] section")->required();
  cmd->add_option("--csv", args->csv, "canonical CSV with inputs and measured outputs")->required();
  cmd->add_option("--variant", args->variant, "model variant, e.g. 2N1Ccolwr")->required();
  cmd->add_option("--out", args->out, "write the identified parameters to this params.json");
  cmd->add_option("--train-start", args->train_start,
                  "first time of the training window (ISO 8601 or unix s; default: first row)");
  cmd->add_option("--train-end", args->train_end,
                  "end of the training window, exclusive (default: after the last row)");
  cmd->add_option("--step", args->step_s,
                  "average the data to this step in seconds first (a multiple of the data step; "
                  "default: the data's own step)")
      ->default_str("");
  cmd->add_option("--test-csv", args->test_csv,
                  "held-out data: print the errors of the identified model on it");
  cmd->add_option("--start", args->start_params,
                  "params.json with start values (e.g. the last calibration: the coarse stage then "
                  "fits all the days from it, without its first fit on every k-th day); "
                  "default Table 3");
  cmd->add_option("--algorithm", args->algorithm,
                  "lad_lm (default: Levenberg-Marquardt on IRLS) or an NLopt method: bobyqa, "
                  "sbplx, nelder_mead, cobyla, lbfgs, mma, crs2_bobyqa, multistart_bobyqa, "
                  "mlsl_bobyqa");
  cmd->add_option("--jacobian", args->jacobian,
                  "how lad_lm (and the gradient methods lbfgs, mma) get their derivatives: "
                  "sensitivities (default: the model run with exact derivatives; the parameters an "
                  "effect's hook reads take differences from it, one run each) or "
                  "differences (forward differences, one model run per free parameter)")
      ->check(CLI::IsMember({"sensitivities", "differences"}));
  cmd->add_option("--free", args->free,
                  "parameters to identify (default: all the variant uses except area_m2 and the "
                  "PV correction coefficients)")
      ->delimiter(',');
  cmd->add_option("--fix", args->fix, "parameters to keep at their start values")->delimiter(',');
  cmd->add_option("--max-evaluations", args->max_evaluations, "simulation budget of the fit")
      ->default_str(std::to_string(IdentOptions::DefaultOptimizerOptions().max_evaluations));
  cmd->add_option("--ftol", args->ftol_rel,
                  "stop when an iteration lowers the MAE by less than this fraction and, for "
                  "lad_lm, its undamped step promised less than 0.3 times that, or before a "
                  "step predicted to gain less than 0.3 times that (than this fraction itself "
                  "in the polish after the coarse stage) (default 1e-3; on synthetic data 1e-4 "
                  "takes longer for a held-out MAE within 0.05 % of the default's)")
      ->check(CLI::PositiveNumber)
      ->default_str("1e-3");
  cmd->add_option("--threads", args->threads,
                  "threads for the runs with exact derivatives, their columns split, for "
                  "the start's cost beside the coarse stage and for the normal equations of "
                  "fits on 65536 rows or more, e.g. 14 days at 15 s (1 or 2; default 2 on a "
                  "machine with two cores or more); the result is the same on either")
      ->check(CLI::Range(1, 2))
      ->default_str("auto");
  cmd->add_option("--parent-pid", args->parent_pid,
                  "exit when the process with this pid ends (used by pvtwin run for its "
                  "calibration child)")
      ->group("");
  cmd->add_flag("--timing", args->timing,
                "print the time split (parse, prepare, fit coarse/fine with their model runs as "
                "counted against the budget and how many of them an earlier run served, "
                "held-out, write) on standard error");
  cmd->add_flag("--use-t-pv", args->use_t_pv,
                "add the measured PV temperature (t_pv_c) to the objective");
  cmd->callback([args] { SetExitCode(RunCalibrate(*args)); });
}

}  // namespace pvtwin::cli
