#include <cstdio>

#include "daemon/bench.h"

namespace pvtwin::cli {

void BenchIdentification(int, std::uint64_t) { std::printf("ident: not built yet\n"); }
void BenchTable6(std::uint64_t) { std::printf("table6: not built yet\n"); }

}  // namespace pvtwin::cli
