#include "daemon/commands.h"

namespace pvtwin::cli {

void RegisterCheckConfig(CLI::App& app) { (void)app; }

}  // namespace pvtwin::cli
