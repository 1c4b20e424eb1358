// pvtwin: command-line entry point. Each verb lives in its own cmd_*.cc and
// registers itself here; commands/usage.h handles help and usage errors.
#include <CLI/CLI.hpp>

#include "daemon/commands/commands.h"
#include "daemon/commands/usage.h"

int main(int argc, char** argv) {
  CLI::App app{
      "pvtwin - a self-calibrating digital twin of a photovoltaic-thermal (PVT) collector "
      "field.\nGrey-box RC model (1 or 2 nodes), identification on operation data, forecasts."};
  app.require_subcommand(1);
  app.set_version_flag("-v,--version", "pvtwin 0.1.0");
  pvtwin::cli::RegisterCommands(app);
  if (const std::optional<int> rc = pvtwin::cli::ParseCommandLine(app, argc, argv)) return *rc;
  return pvtwin::cli::ExitCode();
}
