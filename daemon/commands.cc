#include "daemon/commands.h"

namespace pvtwin::cli {

namespace {
int g_exit_code = kExitOk;
}  // namespace

int ExitCode() { return g_exit_code; }
void SetExitCode(int code) { g_exit_code = code; }

void RegisterCommands(CLI::App& app) {
  RegisterCheckConfig(app);
  RegisterCalibrate(app);
  RegisterSimulate(app);
  RegisterBench(app);
  RegisterBacktest(app);
  RegisterImport(app);
  RegisterExport(app);
  RegisterSim(app);
  RegisterRun(app);
  RegisterDemo(app);
  RegisterDiagnose(app);
}

}  // namespace pvtwin::cli
