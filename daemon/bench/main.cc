// pvtwin-bench: the benchmarks of pvtwin as an executable of their own,
// built with the tree and never installed. The figures are medians over
// repeated runs, printed with each core's time for a fixed workload, so that
// they can be read as ratios on a shared, noisy machine.
#include <CLI/CLI.hpp>

#include "daemon/bench/bench.h"
#include "daemon/commands/commands.h"

namespace pvtwin::cli {

std::string PvtwinExecutable() { return PVTWIN_BINARY; }

}  // namespace pvtwin::cli

int main(int argc, char** argv) {
  CLI::App app;
  pvtwin::cli::ConfigureBench(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return pvtwin::cli::ExitCode();
}
