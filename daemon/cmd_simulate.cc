#include "daemon/commands.h"

namespace pvtwin::cli {

void RegisterSimulate(CLI::App& app) { (void)app; }

}  // namespace pvtwin::cli
