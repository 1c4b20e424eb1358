// pvtwin: command-line entry point. Each verb lives in its own cmd_*.cc and
// registers itself here.
#include <CLI/CLI.hpp>
#include <iostream>

#include "daemon/commands/commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "pvtwin - a self-calibrating digital twin of a photovoltaic-thermal (PVT) collector "
      "field.\nGrey-box RC model (1 or 2 nodes), identification on operation data, forecasts."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pvtwin 0.1.0");
  pvtwin::cli::RegisterCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 uses exit code 0 for --help; bad usage is bad input (2).
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return pvtwin::cli::ExitCode();
}
