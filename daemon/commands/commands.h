// Registration of the pvtwin subcommands. Each cmd_*.cc defines one
// Register<Verb>() that adds its CLI11 subcommand and callback.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace pvtwin::cli {

// Exit codes (doc/contracts.md): 0 success, 1 runtime failure, 2 bad input or config.
inline constexpr int kExitOk = 0;
inline constexpr int kExitRuntime = 1;
inline constexpr int kExitBadInput = 2;

void RegisterCommands(CLI::App& app);

// The verb's one-line summary for the top-level help ("" for none).
std::string VerbSummary(const std::string& verb);

// The exit code chosen by the subcommand that ran.
int ExitCode();
void SetExitCode(int code);

void RegisterCheckConfig(CLI::App& app);
void RegisterSimulate(CLI::App& app);
void RegisterCalibrate(CLI::App& app);
void RegisterBacktest(CLI::App& app);
void RegisterImport(CLI::App& app);
void RegisterImportWeather(CLI::App& app);
void RegisterExport(CLI::App& app);
void RegisterSim(CLI::App& app);
void RegisterRun(CLI::App& app);
void RegisterDemo(CLI::App& app);
void RegisterDiagnose(CLI::App& app);
void RegisterUpload(CLI::App& app);
void RegisterPoll(CLI::App& app);
void RegisterMigrate(CLI::App& app);

}  // namespace pvtwin::cli
