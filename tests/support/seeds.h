// The seeds a statistical test runs: a comma-separated list in an
// environment variable (development or final-check seeds, given by hand,
// doc/validation.md), else the suite's own.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace pvtwin::testing {

inline std::vector<std::uint64_t> SeedsFromEnv(const char* variable, const char* suite_seeds) {
  const char* env = std::getenv(variable);
  std::vector<std::uint64_t> seeds;
  std::stringstream list(env != nullptr ? env : suite_seeds);
  std::string item;
  while (std::getline(list, item, ',')) seeds.push_back(std::stoull(item));
  return seeds;
}

}  // namespace pvtwin::testing
