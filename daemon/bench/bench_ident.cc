// pvtwin-bench ident: the figures behind the choice of the identification
// algorithm (IdentOptions::method). Synthetic data with a known answer:
// 17 days of a 2N1Ccolwr "truth" (ReferenceTruthParams) with realistic
// sensor noise; the first 14 days train, the last 3 are held out. Every
// identification runs on the calling thread (one core); runtimes are
// medians over repeated runs.
//
// Printed:
//   1. the noise floor: the objective of the true parameters;
//   2. each algorithm on 14 days at 1 min from StartParams: runtime,
//      simulations, train MAE (the objective) and held-out MAE (P_el + Q_u
//      per m², the paper's objective), also relative to the reference;
//   3. the reference: a long multi-start BOBYQA run;
//   4. the speed targets of the default (lad_lm) at 1 min and at 5 s, with
//      the 5-s fit's split into its coarse stages and the fine stage at 5 s;
//   5. the paper's MATLAB figures;
//   6. the time split of the default at 1 min: parse (the training CSV file,
//      read as `calibrate` reads it), fit coarse / fine with their model
//      runs, write (params.json);
//   7. the whole `pvtwin calibrate` process on the 1-min training days (what
//      issue 16's 50 ms is for) and on the 5-s ones: this executable run as
//      a child, and its start and exit alone (`--version`).
// The 1-min training and held-out days are written to the data directory
// (a temporary one without --data-dir, removed afterwards) as train.csv and
// held_out.csv, the 5-s training days as train_5s.csv, with plant.toml, the
// example plant's [plant] section (config/examples/plant.toml), so that
// `pvtwin calibrate` runs on them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "config/plant_config.h"
#include "core/fit/identification.h"
#include "core/model/thermal_model.h"
#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"
#include "io/platform/child_process.h"
#include "io/files/csv.h"
#include "io/files/params_json.h"

namespace pvtwin::cli {

namespace {

constexpr int kIdentTrainDays = 14;
constexpr int kIdentHeldOutDays = 3;
constexpr const char* kVariant = "2N1Ccolwr";
// Issue 16's target for the whole `pvtwin calibrate` process at 1 min.
constexpr double kTargetProcessS = 0.05;
// Issue 16's target for 14 days at 5 s.
constexpr double kTarget5sS = 0.3;

// A data set split into the training window and the held-out days.
struct SplitData {
  double step_s = 0.0;
  std::size_t rows = 0;
  Series train, held_out;
  Drivers train_drivers, held_out_drivers;
  Measurements train_meas, held_out_meas;
};

// Generates kIdentTrainDays + kIdentHeldOutDays of synthetic data at step_s and splits
// it. False (and *error) if the drivers cannot be built.
bool MakeSplitData(const Plant& plant, const ModelSpec& spec, double step_s, std::uint64_t seed,
                   SplitData* out, std::string* error) {
  WeatherOptions weather;
  weather.num_days = kIdentTrainDays + kIdentHeldOutDays;
  weather.step_s = step_s;
  weather.seed = seed;
  const Series data = MakeSyntheticPlantData(plant, weather, spec, ReferenceTruthParams(plant),
                                             RealisticSensorNoise(seed));
  const auto train_rows = static_cast<std::size_t>(kIdentTrainDays * 86400.0 / step_s + 0.5);
  if (data.size() <= train_rows) {
    *error = "the generated series is shorter than the training window";
    return false;
  }
  out->step_s = step_s;
  out->rows = data.size();
  out->train = data.Slice(0, train_rows);
  out->held_out = data.Slice(train_rows, data.size());
  if (!PrepareDrivers(out->train, plant, spec, &out->train_drivers, error) ||
      !PrepareDrivers(out->held_out, plant, spec, &out->held_out_drivers, error)) {
    return false;
  }
  out->train_meas = MakeMeasurements(out->train, out->train_drivers);
  out->held_out_meas = MakeMeasurements(out->held_out, out->held_out_drivers);
  return true;
}

std::vector<Channel> ChannelsOf(const Series& s) {
  std::vector<Channel> channels;
  for (const ChannelInfo& info : kChannels) {
    if (s.Has(info.channel)) channels.push_back(info.channel);
  }
  return channels;
}

// Writes `series` into dir as `name`, saying so.
void WriteDataFile(const std::string& dir, const char* name, const Series& series) {
  std::string error;
  const std::string path = dir + "/" + name;
  if (!WriteCsv(path, series, ChannelsOf(series), &error)) {
    std::printf("ident: %s\n", error.c_str());
    return;
  }
  std::printf("ident: wrote %s (%zu rows)\n", path.c_str(), series.size());
}

// The time split of the default at 1 min: median parse time of the training
// CSV (dir/train.csv, read as `calibrate` reads it; from text in memory when
// there is no directory), the fit's stages from its summary, and the median
// time to format and write params.json.
void PrintTimeSplit(const SplitData& data, const IdentSummary& fit, const std::string& dir,
                    int runs) {
  std::ostringstream text;
  WriteCsv(text, data.train, ChannelsOf(data.train));
  const std::string csv = text.str();
  std::vector<double> parse, write;
  const std::string out_path = "/tmp/pvtwin-bench-ident-params.json";
  for (int r = 0; r < runs; ++r) {
    Series s;
    Diagnostics errors, warnings;
    CsvReadOptions options;
    options.area_m2 = data.train_drivers.plant.area_m2;
    const auto t0 = std::chrono::steady_clock::now();
    if (dir.empty()) {
      std::istringstream in(csv);
      ParseCanonicalCsv(in, "train.csv", options, &s, &errors, &warnings);
    } else {
      ReadCanonicalCsv(dir + "/train.csv", options, &s, &errors, &warnings);
    }
    parse.push_back(SecondsSince(t0));
    const auto t1 = std::chrono::steady_clock::now();
    std::string error;
    WriteTextFileAtomically(
        out_path,
        FormatParamsJson(fit.variant, fit.params, UsedParams(data.train_drivers.spec), "{}"),
        &error);
    write.push_back(SecondsSince(t1));
  }
  std::remove(out_path.c_str());
  std::printf(
      "\ntime split of the default (lad_lm) at 1 min, ms (parse and write: median of %d runs; "
      "fit: the last run)\n",
      runs);
  // As `calibrate --timing` says it: only when a fit on a day subset ran.
  const std::string subset_text = fit.CoarseSubsetText();
  const std::string subset = subset_text.empty() ? "" : ", " + subset_text;
  std::printf(
      "  parse %.1f (%zu kB of CSV) | fit %.1f = coarse %.1f (%d model runs%s) + fine %.1f "
      "(%d model runs; of it identifiability %.1f, %d runs, trial fits %.1f); %d of the runs "
      "with sensitivities, each counted as %d | write %.2f\n",
      1e3 * Median(parse), csv.size() / 1024, 1e3 * fit.runtime_s, 1e3 * fit.coarse_runtime_s,
      fit.coarse_evaluations, subset.c_str(), 1e3 * (fit.runtime_s - fit.coarse_runtime_s),
      fit.evaluations - fit.coarse_evaluations, 1e3 * fit.fixing_runtime_s, fit.fixing_evaluations,
      1e3 * fit.trial_runtime_s, fit.sensitivity_runs, kSensitivityRunCost, 1e3 * Median(write));
}

// Wall time of this executable run with `args` (output to /dev/null) until
// it ends; NaN when it cannot be started or does not exit with 0.
double ProcessSeconds(const std::vector<std::string>& args) {
  std::vector<std::string> argv{PvtwinExecutable()};
  argv.insert(argv.end(), args.begin(), args.end());
  ChildProcess child;
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  if (!child.Start(argv, "/dev/null", &error)) return std::nan("");
  const int exit_code = child.Wait();
  const double seconds = SecondsSince(start);
  return exit_code == 0 ? seconds : std::nan("");
}

// The example plant of the synthetic data (DesignExamplePlant) as a config
// file, checked against it: false (and a printed reason) if the two differ.
bool WriteExamplePlantConfig(const std::string& path) {
  const std::string text =
      "# DesignExamplePlant (core/synth/synthetic_plant.h), written by pvtwin-bench ident\n"
      "[plant]\nlatitude_deg = 47.358\nlongitude_deg = 16.128\ntilt_deg = 20\n"
      "azimuth_deg = 180\narea_m2 = 1.8\n";
  std::string error;
  Config config;
  Diagnostics errors;
  if (!WriteTextFileAtomically(path, text, &error) || !LoadConfig(path, &config, &errors)) {
    std::printf("ident: %s: %s\n", path.c_str(),
                error.empty() ? errors.front().ToString().c_str() : error.c_str());
    return false;
  }
  if (!(config.plant == DesignExamplePlant())) {
    std::printf("ident: %s does not give DesignExamplePlant(); no process figures\n", path.c_str());
    return false;
  }
  return true;
}

// Median wall time of `runs` runs of `pvtwin calibrate` on `csv` (the run's
// own and the --version figures interleaved), with min and max; false when
// a run failed.
struct ProcessFigures {
  double median_s = 0.0, min_s = 0.0, max_s = 0.0, version_median_s = 0.0;
};
bool TimeCalibrateProcess(const std::string& dir, const std::string& csv, int runs,
                          ProcessFigures* f) {
  const std::string out = dir + "/params.json";
  const std::vector<std::string> calibrate = {"calibrate", "--config", dir + "/plant.toml",
                                              "--csv",     csv,        "--variant",
                                              kVariant,    "--out",    out};
  std::vector<double> whole, start;
  for (int r = 0; r < runs; ++r) {
    whole.push_back(ProcessSeconds(calibrate));
    start.push_back(ProcessSeconds({"--version"}));
  }
  std::remove(out.c_str());
  if (std::any_of(whole.begin(), whole.end(), [](double t) { return std::isnan(t); })) {
    return false;
  }
  f->median_s = Median(whole);
  f->min_s = *std::min_element(whole.begin(), whole.end());
  f->max_s = *std::max_element(whole.begin(), whole.end());
  f->version_median_s = Median(start);
  return true;
}

// 7. The whole calibrate process on dir/train.csv (median of `runs`), and
// the executable's start and exit alone; with the 5-s days, on
// dir/train_5s.csv too (median of `runs_5s`).
void PrintProcessTimes(const std::string& dir, bool have_5s, int runs, int runs_5s) {
  if (!WriteExamplePlantConfig(dir + "/plant.toml")) return;
  ProcessFigures f;
  if (!TimeCalibrateProcess(dir, dir + "/train.csv", runs, &f)) {
    std::printf("\nwhole process: `pvtwin calibrate` on %s/train.csv FAILED\n", dir.c_str());
    return;
  }
  std::printf(
      "\nwhole process at 1 min (`pvtwin calibrate --variant %s` on train.csv, wall time, "
      "median of %d runs): %.1f ms (min %.1f, max %.1f; target %.0f ms); the executable's start "
      "and exit alone (`pvtwin --version`, median of %d): %.1f ms\n",
      kVariant, runs, 1e3 * f.median_s, 1e3 * f.min_s, 1e3 * f.max_s, 1e3 * kTargetProcessS, runs,
      1e3 * f.version_median_s);
  if (!have_5s) return;
  if (!TimeCalibrateProcess(dir, dir + "/train_5s.csv", runs_5s, &f)) {
    std::printf("whole process: `pvtwin calibrate` on %s/train_5s.csv FAILED\n", dir.c_str());
    return;
  }
  std::printf(
      "whole process at 5 s (on train_5s.csv, median of %d runs): %.3f s (min %.3f, max %.3f; "
      "the fit's target %.1f s)\n",
      runs_5s, f.median_s, f.min_s, f.max_s, kTarget5sS);
}

// The paper's objective (MAE of P_el + MAE of Q_u, W/m²) of `params` on
// the given data; NaN if the simulation gives NaN in an objective row.
double ObjectiveWM2(const Drivers& drivers, const Measurements& meas, const ParamVector& params) {
  SimOutputs sim;
  Simulate(drivers, params, &sim);
  return ComputeErrors(meas, sim, drivers.plant.area_m2).objective_w_m2();
}

// Identifications of one configuration repeated `runs` times.
struct FitFigures {
  std::string algorithm;
  std::string jacobian;  // JacobianOf
  int runs = 0;
  double median_runtime_s = 0.0;
  IdentSummary summary;  // of the last run (the fits are deterministic)
  double held_out_w_m2 = std::nan("");
};

// How the search got its derivatives: "-" for a derivative-free method (its
// one run with sensitivities is the identifiability analysis's), "sens" when
// runs with sensitivities served it, else "diff" (forward differences).
std::string JacobianOf(const FitFigures& f, const IdentOptions& options) {
  const bool derivatives =
      options.method == IdentMethod::kLadLm || NeedsGradient(options.optimizer.algorithm);
  if (!derivatives) return "-";
  return f.summary.sensitivity_runs > 0 ? "sens" : "diff";
}

FitFigures RunFits(const SplitData& data, const ParamVector& start, const IdentOptions& options,
                   int runs) {
  FitFigures f;
  f.algorithm = IdentAlgorithmName(options);
  std::vector<double> times;
  for (int r = 0; r < runs; ++r) {
    std::fprintf(stderr, "bench ident: %s, %zu rows at %g s, run %d/%d ...", f.algorithm.c_str(),
                 data.train_meas.size(), data.step_s, r + 1, runs);
    std::fflush(stderr);
    const auto t0 = std::chrono::steady_clock::now();
    f.summary = Identify(data.train_drivers, data.train_meas, start, options);
    times.push_back(SecondsSince(t0));
    std::fprintf(stderr, " %.2f s, %s\n", times.back(),
                 f.summary.ok ? "ok" : f.summary.failure_reason.c_str());
    if (!f.summary.ok) break;  // a failure is reported, not timed again
  }
  f.runs = static_cast<int>(times.size());
  f.median_runtime_s = Median(times);
  f.jacobian = JacobianOf(f, options);
  if (f.summary.ok) {
    f.held_out_w_m2 = ObjectiveWM2(data.held_out_drivers, data.held_out_meas, f.summary.params);
  }
  return f;
}

// "1.234" or "-" when the value is not finite.
std::string Num(double v, const char* format) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

// "8/10": parameters left free after fixing the undetermined ones, of those
// identified.
std::string FreeCount(const IdentSummary& s) {
  int free = 0, identified = 0;
  for (const ParamEstimate& e : s.estimates) {
    identified += e.free ? 1 : 0;
    free += e.free && !e.undetermined ? 1 : 0;
  }
  return std::to_string(free) + "/" + std::to_string(identified);
}

void PrintFitRow(const FitFigures& f, double reference_held_out_w_m2) {
  std::printf("  %-22s %-4s %9.3f %5d %7d %5d  ", f.algorithm.c_str(), f.jacobian.c_str(),
              f.median_runtime_s, f.runs, f.summary.evaluations, f.summary.sensitivity_runs);
  if (!f.summary.ok) {
    std::printf("FAILED: %s\n", f.summary.failure_reason.c_str());
    return;
  }
  const std::string term(ToString(f.summary.termination));
  std::printf("%-18s %5s %9.4f %9.4f %7s\n", ("ok/" + term).c_str(), FreeCount(f.summary).c_str(),
              f.summary.final_cost_w_m2, f.held_out_w_m2,
              Num(f.held_out_w_m2 / reference_held_out_w_m2, "%.4f").c_str());
}

// 2. The algorithm comparison: every method from StartParams, and the
// default's variations; rows printed against the reference's held-out MAE.
std::vector<FitFigures> CompareAlgorithms(const SplitData& d1, const ParamVector& start,
                                          int repeats, int slow_runs, double ref_held_out) {
  const std::vector<std::string> algorithms = {
      "lad_lm",      "bobyqa", "sbplx", "nelder_mead", "multistart_bobyqa",
      "crs2_bobyqa", "lbfgs",  "mma"};
  std::vector<FitFigures> table;
  for (const std::string& name : algorithms) {
    IdentOptions options;
    if (!SetIdentAlgorithm(name, &options)) {
      FitFigures f;
      f.algorithm = name;
      f.summary.failure_reason = "unknown algorithm";
      table.push_back(f);
      continue;
    }
    if (options.method == IdentMethod::kNlopt) {
      options.optimizer.max_evaluations = 6000;
      options.optimizer.ftol_rel = 1e-6;
    }
    table.push_back(RunFits(d1, start, options, name == "lad_lm" ? repeats : slow_runs));
  }
  // The default method with the tighter stop, with the other Jacobian, and
  // both; the gradient method with differences.
  auto variation = [&](const char* label, double ftol, bool analytic, const char* algorithm,
                       int runs) {
    IdentOptions options;
    SetIdentAlgorithm(algorithm, &options);
    if (options.method == IdentMethod::kNlopt) options.optimizer.max_evaluations = 6000;
    options.optimizer.ftol_rel = ftol;
    options.analytic_jacobian = analytic;
    FitFigures f = RunFits(d1, start, options, runs);
    f.algorithm = label;
    table.push_back(f);
  };
  variation("lad_lm ftol 1e-4", 1e-4, true, "lad_lm", slow_runs);
  variation("lad_lm diff.", IdentOptions{}.optimizer.ftol_rel, false, "lad_lm", slow_runs);
  variation("lad_lm diff. ftol 1e-4", 1e-4, false, "lad_lm", slow_runs);
  variation("lbfgs diff.", 1e-6, false, "lbfgs", slow_runs);
  std::printf(
      "\nalgorithms: %d days at 1 min from StartParams, default IdentOptions (lad_lm: ftol_rel "
      "%g) unless named; NLopt methods with max_evaluations 6000, ftol_rel 1e-6; median runtime "
      "over %d (lad_lm) or %d runs; J: derivatives from the runs with sensitivities (sens, each "
      "counted as %d sims) or forward differences (diff)\n",
      kIdentTrainDays, IdentOptions{}.optimizer.ftol_rel, repeats, slow_runs, kSensitivityRunCost);
  std::printf("  %-22s %-4s %9s %5s %7s %5s  %-18s %5s %9s %9s %7s\n", "algorithm", "J", "median s",
              "runs", "sims", "sens", "status", "free", "train", "held-out", "/ref");
  for (const FitFigures& f : table) PrintFitRow(f, ref_held_out);

  return table;
}

// 4. Speed targets of the default, on one core and with the runs with
// sensitivities split over two threads as `calibrate` runs them; the 5-s
// fit (written to dir as train_5s.csv) comes back in *fit_5s.
bool PrintSpeedTargets(const Plant& plant, const ModelSpec& spec, std::uint64_t seed,
                       const SplitData& d1, const FitFigures& fit_1min, const FitFigures& ref,
                       const ParamVector& start, const std::string& dir, int repeats,
                       int slow_runs, FitFigures* fit_5s_out) {
  const ParamVector truth = ReferenceTruthParams(plant);
  const double ref_held_out = ref.held_out_w_m2;
  IdentOptions two_threads;
  two_threads.threads = 2;
  const FitFigures fit_1min_two = RunFits(d1, start, two_threads, repeats);
  SplitData d5;
  std::string error5;
  const bool have_5s = MakeSplitData(plant, spec, 5.0, seed, &d5, &error5);
  FitFigures fit_5s, fit_5s_two;
  double ref_held_out_5s = std::nan("");
  double floor_held_out_5s = std::nan("");
  if (have_5s) {
    if (!dir.empty()) WriteDataFile(dir, "train_5s.csv", d5.train);
    fit_5s = RunFits(d5, start, IdentOptions{}, slow_runs);
    fit_5s_two = RunFits(d5, start, two_threads, slow_runs);
    if (ref.summary.ok) {
      ref_held_out_5s = ObjectiveWM2(d5.held_out_drivers, d5.held_out_meas, ref.summary.params);
    }
    floor_held_out_5s = ObjectiveWM2(d5.held_out_drivers, d5.held_out_meas, truth);
  }
  std::printf(
      "\nspeed targets of the default (lad_lm), one core and (2 thr.) the runs with "
      "sensitivities split over two threads as `calibrate` runs them (the same fit); held-out "
      "MAE against the reference's parameters on the same held-out days\n");
  std::printf("  %-28s %9s %5s %9s %9s  %-10s %9s %9s %9s\n", "case", "median s", "runs",
              "target s", "/target", "status", "held-out", "ref", "/ref");
  auto target_row = [](const char* label, const FitFigures& f, double target_s, double ref_w_m2) {
    std::printf("  %-28s %9.3f %5d %9.2f %9.3f  ", label, f.median_runtime_s, f.runs, target_s,
                f.median_runtime_s / target_s);
    if (!f.summary.ok) {
      std::printf("FAILED: %s\n", f.summary.failure_reason.c_str());
      return;
    }
    std::printf("%-10s %9.4f %9s %9s\n", "ok", f.held_out_w_m2, Num(ref_w_m2, "%.4f").c_str(),
                Num(f.held_out_w_m2 / ref_w_m2, "%.4f").c_str());
  };
  char label[64];
  std::snprintf(label, sizeof(label), "(a) 14 d at 1 min, %zu rows", d1.train_meas.size());
  // Issue 16's targets: the whole `calibrate` process at 1 min within 50 ms
  // (timed as a process under 7.), so the fit alone must be below; 5 s
  // within 0.3 s.
  target_row(label, fit_1min, kTargetProcessS, ref_held_out);
  target_row("    2 thr.", fit_1min_two, kTargetProcessS, ref_held_out);
  if (have_5s) {
    std::snprintf(label, sizeof(label), "(b) 14 d at 5 s, %zu rows", d5.train_meas.size());
    target_row(label, fit_5s, kTarget5sS, ref_held_out_5s);
    target_row("    2 thr.", fit_5s_two, kTarget5sS, ref_held_out_5s);
    std::printf("  noise floor on the 5-s held-out days (true parameters): %.4f W/m2\n",
                floor_held_out_5s);
    if (fit_5s.summary.ok) {
      const IdentSummary& s5 = fit_5s.summary;
      std::printf(
          "  5-s fit split (the last run), ms: coarse stages at 1 and 5 min %.1f (%d model runs) "
          "+ fine at 5 s %.1f (%d); %d of the runs with sensitivities\n",
          1e3 * s5.coarse_runtime_s, s5.coarse_evaluations,
          1e3 * (s5.runtime_s - s5.coarse_runtime_s), s5.evaluations - s5.coarse_evaluations,
          s5.sensitivity_runs);
    }
  } else {
    std::printf("  (b) 14 d at 5 s: FAILED: %s\n", error5.c_str());
  }

  *fit_5s_out = fit_5s;
  return have_5s;
}

}  // namespace

void BenchIdentification(int repeats, std::uint64_t seed, const std::string& data_dir) {
  const auto bench_start = std::chrono::steady_clock::now();
  const Plant plant = DesignExamplePlant();
  ModelSpec spec;
  std::string error;
  if (!ParseVariant(kVariant, &spec, &error)) {
    std::printf("ident: %s: %s\n", kVariant, error.c_str());
    return;
  }
  const ParamVector truth = ReferenceTruthParams(plant);
  const ParamVector start = StartParams(plant);
  const int slow_runs = std::min(repeats, 3);

  std::printf(
      "ident: identification of %s on synthetic data (truth %s, ReferenceTruthParams, realistic "
      "sensor noise), seed %llu\n",
      kVariant, kVariant, static_cast<unsigned long long>(seed));
  std::printf("machine: 1 core used of %u (hardware_concurrency); build %s\n",
              std::thread::hardware_concurrency(),
#ifdef NDEBUG
              "NDEBUG"
#else
              "with assertions"
#endif
  );

  // 1. Data and noise floor.
  SplitData d1;
  if (!MakeSplitData(plant, spec, 60.0, seed, &d1, &error)) {
    std::printf("ident: 1-min data: %s\n", error.c_str());
    return;
  }
  std::printf(
      "\ndata: %d days at 1 min (%zu rows): train = first %d days (%zu rows, %zu in the "
      "objective), held-out = last %d days (%zu rows, %zu in the objective)\n",
      kIdentTrainDays + kIdentHeldOutDays, d1.rows, kIdentTrainDays, d1.train_meas.size(),
      d1.train_meas.rows.size(), kIdentHeldOutDays, d1.held_out_meas.size(),
      d1.held_out_meas.rows.size());
  // Where train.csv and held_out.csv go (7. runs `pvtwin calibrate` on them).
  std::string dir = data_dir;
  if (dir.empty()) {
    char scratch[] = "/tmp/pvtwin-bench-ident-XXXXXX";
    if (mkdtemp(scratch) != nullptr) dir = scratch;
  }
  if (!dir.empty()) {
    WriteDataFile(dir, "train.csv", d1.train);
    WriteDataFile(dir, "held_out.csv", d1.held_out);
  }
  std::printf("objective (MAE P_el + MAE Q_u, W/m2)   %10s %10s\n", "train", "held-out");
  std::printf("  true parameters (noise floor)        %10.4f %10.4f\n",
              ObjectiveWM2(d1.train_drivers, d1.train_meas, truth),
              ObjectiveWM2(d1.held_out_drivers, d1.held_out_meas, truth));
  std::printf("  start parameters (StartParams)       %10.4f %10.4f\n",
              ObjectiveWM2(d1.train_drivers, d1.train_meas, start),
              ObjectiveWM2(d1.held_out_drivers, d1.held_out_meas, start));
  std::fflush(stdout);

  // 3 (run first: the table's ratios refer to it). The reference.
  IdentOptions ref_options;
  SetIdentAlgorithm("multistart_bobyqa", &ref_options);
  ref_options.optimizer.max_evaluations = 40000;
  ref_options.optimizer.multistart_count = 16;
  ref_options.optimizer.ftol_rel = 1e-8;
  const FitFigures ref = RunFits(d1, start, ref_options, 1);
  const double ref_held_out = ref.held_out_w_m2;

  // 2. Algorithm comparison.
  const std::vector<FitFigures> table = CompareAlgorithms(d1, start, repeats, slow_runs, ref_held_out);

  // 3. The reference, printed.
  std::printf(
      "\nreference: multistart_bobyqa, max_evaluations 40000, multistart_count 16, ftol_rel "
      "1e-8, one run\n");
  PrintFitRow(ref, ref_held_out);
  for (const std::string& note : ref.summary.notes) std::printf("    %s\n", note.c_str());
  std::fflush(stdout);

  // 4. Speed targets of the default.
  const FitFigures& fit_1min = table.front();  // lad_lm, `repeats` runs
  FitFigures fit_5s;
  const bool have_5s = PrintSpeedTargets(plant, spec, seed, d1, fit_1min, ref, start, dir, repeats,
                                         slow_runs, &fit_5s);

  // 5. The paper.
  std::printf(
      "\npaper (MATLAB lsqnonlin): 75 s for 14 days at 1 min (Table 6), 1403 s at 5-s steps "
      "(Table 5)");
  if (fit_1min.summary.ok && fit_1min.median_runtime_s > 0.0) {
    std::printf("; here %.0fx", 75.0 / fit_1min.median_runtime_s);
    if (have_5s && fit_5s.summary.ok && fit_5s.median_runtime_s > 0.0) {
      std::printf(" and %.0fx", 1403.0 / fit_5s.median_runtime_s);
    }
    std::printf(" faster (different machines)");
  }
  if (fit_1min.summary.ok) PrintTimeSplit(d1, fit_1min.summary, dir, repeats);
  if (!dir.empty()) PrintProcessTimes(dir, have_5s, std::max(repeats, 11), slow_runs);
  if (data_dir.empty() && !dir.empty()) std::filesystem::remove_all(dir);
  std::printf("\nident: done in %.1f s\n", SecondsSince(bench_start));
}

}  // namespace pvtwin::cli
