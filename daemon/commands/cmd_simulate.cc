// pvtwin simulate: run one variant with given parameters over measured inputs.
#include <iostream>

#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "io/files/csv.h"
#include "io/files/params_json.h"

namespace pvtwin::cli {

namespace {

struct SimulateArgs {
  std::string config;
  std::string csv;
  std::string variant;
  std::string params;
  std::string out;
};

int RunSimulate(const SimulateArgs& a) {
  Config config;
  if (!LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  ModelSpec spec;
  if (!ParseVariantOrReport(a.variant, &spec)) return kExitBadInput;
  ParamsFile params;
  params.values = StartParams(config.plant);
  if (a.params.empty()) {
    std::cerr << "warning: no --params: simulating with the start values of the paper's Table 3, "
                 "not identified ones (pvtwin calibrate --out params.json identifies them)\n";
  } else {
    Diagnostics errors;
    if (!ReadParamsJson(a.params, config.plant, &params, &errors)) {
      for (const Diagnostic& d : errors) std::cerr << d.ToString() << "\n";
      return kExitBadInput;
    }
    if (!params.variant.empty() && params.variant != spec.Name()) {
      std::cerr << "warning: " << a.params << " was identified for variant " << params.variant
                << ", simulating " << spec.Name() << "\n";
    }
  }
  Series series;
  if (!LoadCsvOrReport(a.csv, config, &series)) return kExitBadInput;
  Drivers drivers;
  if (!PrepareDriversOrReport(series, a.csv, config, spec, &drivers)) return kExitBadInput;

  SimOutputs sim;
  Simulate(drivers, params.values, &sim);
  Series pred;
  pred.time_s = series.time_s;
  pred.step_s = series.step_s;
  pred[Channel::kPElW] = sim.p_el_w;
  pred[Channel::kQThW] = sim.q_th_w;
  pred[Channel::kTPvC] = sim.t_pv_c;
  pred[Channel::kTOutC] = sim.t_out_c;
  const Channel columns[] = {Channel::kPElW, Channel::kQThW, Channel::kTPvC, Channel::kTOutC};
  if (!WriteCsvOrReport(a.out, pred, columns)) return kExitRuntime;
  if (!a.out.empty() && a.out != "-") {
    std::cerr << "wrote " << pred.size() << " rows to " << a.out << "\n";
  }
  return kExitOk;
}

}  // namespace

void RegisterSimulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Run a model variant with given parameters over measured inputs (what-if runs).\n"
      "Writes time, p_el_w, q_th_w, t_pv_c, t_out_c as CSV. Rows whose inputs are missing\n"
      "are written with empty predictions; the states restart after them.");
  cmd->add_option("--config", args->config, "TOML config with the [plant] section")->required();
  cmd->add_option("--csv", args->csv, "canonical CSV with the measured inputs")->required();
  cmd->add_option("--variant", args->variant,
                  "model variant, e.g. 2N1Ccolwr, 1N1Cwr+transport_delay "
                  "(grammar {1,2}N[1C|1Cpv|1Ccol|2C][w][r][I][+effect...])")
      ->required();
  cmd->add_option("--params", args->params,
                  "params.json (from calibrate); parameters not given take Table 3 start values");
  cmd->add_option("--out", args->out, "output CSV (default: standard output)");
  cmd->callback([args] { SetExitCode(RunSimulate(*args)); });
}

}  // namespace pvtwin::cli
