// Benchmarks of pvtwin bench, shared helpers.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "core/plant.h"

namespace pvtwin::cli {

double Median(std::vector<double> v);
double SecondsSince(std::chrono::steady_clock::time_point start);
// DESIGN.md's example plant (47.358°N, 16.128°E, 20° tilt, south, 1.8 m²).
Plant BenchPlant();

void BenchIdentification(int repeats, std::uint64_t seed);
void BenchTable6(std::uint64_t seed);

}  // namespace pvtwin::cli
