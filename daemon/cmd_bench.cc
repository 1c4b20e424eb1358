#include "daemon/commands.h"

namespace pvtwin::cli {

void RegisterBench(CLI::App& app) { (void)app; }

}  // namespace pvtwin::cli
