// The benchmarks of pvtwin-bench (daemon/bench/main.cc), shared helpers.
// pvtwin-bench is built with the tree but never installed: benchmarks and
// the scratch PostgreSQL server they start (tests/support/) stay out of the
// product.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/clock.h"

namespace pvtwin::cli {

double Median(std::vector<double> v);
// User plus system CPU seconds of this process so far (getrusage).
double SelfCpuSeconds();
using pvtwin::SecondsSince;  // core/common/clock.h

// The pvtwin executable the benchmarks start as child processes (`run`,
// `calibrate`): the one built beside pvtwin-bench.
std::string PvtwinExecutable();

// The benchmarks' command line on the top level of pvtwin-bench.
void ConfigureBench(CLI::App& app);

// data_dir: where to write the 1-min training and held-out CSVs ("" = nowhere).
void BenchIdentification(int repeats, std::uint64_t seed, const std::string& data_dir);
void BenchTable6(std::uint64_t seed);
void BenchStore(int repeats, std::uint64_t seed);
// Real processes, real time: CPU and memory of `pvtwin run` over `seconds`.
void BenchDaemon(double seconds);
void BenchPoll(int cycles, std::uint64_t seed);
void BenchEffects(int repeats, std::uint64_t seed);
void BenchDiagnosis(std::uint64_t seed);
// A 30-day backlog of 1-min rows into a PostgreSQL started for the purpose.
void BenchUpload(std::uint64_t seed);

}  // namespace pvtwin::cli
