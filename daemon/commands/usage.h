// The command line as a user meets it: `pvtwin help [VERB]`, unknown verbs
// and options named with their nearest match, every missing required option
// named at once, one line per verb in the top-level help.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

namespace pvtwin::cli {

// Levenshtein distance between a and b.
std::size_t EditDistance(const std::string& a, const std::string& b);

// The candidate nearest to `word`: within edit distance 2, or one that
// `word` is a prefix of (or that is a prefix of `word`), the smallest distance
// first; nullopt when none is near.
std::optional<std::string> NearestMatch(const std::string& word,
                                        const std::vector<std::string>& candidates);

// Parses argv into `app` (RegisterCommands done) and returns the exit code
// to leave with when the command line itself settles it (help, version,
// usage errors: 0 or 2), nullopt when the chosen verb ran.
std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv);

}  // namespace pvtwin::cli
