// Benchmarks of pvtwin bench, shared helpers.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace pvtwin::cli {

double Median(std::vector<double> v);
double SecondsSince(std::chrono::steady_clock::time_point start);

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
