// pvtwin export: a time range of the SQLite store as canonical CSV.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <vector>

#include "core/data/aggregate.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/store_cli.h"
#include "io/files/csv.h"
#include "io/store/store.h"

namespace pvtwin::cli {

namespace {

struct ExportArgs {
  std::string config;
  std::string db;
  std::string from;
  std::string to = "now";
  std::string table = "1min";
  std::string out;
};

// The poll period of stored samples: their most common spacing (the store
// does not record it; a config says it).
double SamplePeriodS(const std::vector<Sample>& samples) {
  std::vector<std::int64_t> steps;
  for (std::size_t i = 1; i < samples.size(); ++i)
    steps.push_back(samples[i].ts_s - samples[i - 1].ts_s);
  if (steps.empty()) return 5.0;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                   steps.end());
  return static_cast<double>(std::max<std::int64_t>(1, steps[steps.size() / 2]));
}

int RunExport(const ExportArgs& a) {
  Config config;  // without --config: the defaults, enough to read a store
  if (a.config.empty() && a.db.empty()) {
    std::cerr << "export: give --db (the SQLite file) or --config (its [storage] path)\n";
    return kExitBadInput;
  }
  if (!a.config.empty() && !LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  std::int64_t from_ts = 0, to_ts = 0;
  if (!ParseTimeOrReport("--from", a.from, &from_ts) || !ParseTimeOrReport("--to", a.to, &to_ts)) {
    return kExitBadInput;
  }
  if (to_ts <= from_ts) {
    std::cerr << "--to = " << a.to << ": must be later than --from = " << a.from << "\n";
    return kExitBadInput;
  }
  const std::string path = a.db.empty() ? config.storage.path : a.db;
  if (!std::filesystem::exists(path)) {
    std::cerr << (a.db.empty() ? "[storage] path = " : "--db = ") << path << ": no such database\n";
    return kExitBadInput;
  }
  std::unique_ptr<Store> store;
  if (!OpenStoreReadOnlyOrReport(path, StoreOptionsFor(config), &store)) return kExitRuntime;

  Series series;
  std::string error;
  bool ok = false;
  if (a.table == "5s") {
    std::vector<Sample> samples;
    ok = store->ReadSamples(from_ts, to_ts, &samples, &error);
    series = SeriesFromSamples(samples,
                               a.config.empty() ? SamplePeriodS(samples) : config.poll.period_s);
  } else if (a.table == "interval") {
    ok = store->ReadIntervalRows(from_ts, to_ts, &series, &error);
  } else {
    ok = store->ReadMinutes(from_ts, to_ts, &series, &error);
  }
  if (!ok) {
    std::cerr << error << "\n";
    return kExitRuntime;
  }
  std::vector<Channel> channels;  // those with a value somewhere, in canonical order
  for (const ChannelInfo& info : kChannels) {
    if (series.Has(info.channel)) channels.push_back(info.channel);
  }
  if (!WriteCsvOrReport(a.out, series, channels)) return kExitRuntime;
  const char* table = a.table == "5s"         ? "sample_5s"
                      : a.table == "interval" ? "measurement_interval"
                                              : "measurement_1min";
  std::cerr << "exported " << series.size() << " rows of " << table << " from " << path << "\n";
  return kExitOk;
}

}  // namespace

void RegisterExport(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a time range [--from, --to) of the SQLite store as canonical CSV: time (ISO 8601\n"
      "UTC, start of the interval) and every channel that has a value in the range. The\n"
      "1-min table has the averaged, corrected measurements; the 5s table the raw samples;\n"
      "the interval table the rows of a coarser logger imported at their own step.");
  cmd->add_option("--config", args->config,
                  "TOML config ([storage] path, [poll] period_s, [plant]); optional with --db");
  cmd->add_option("--from", args->from,
                  "first time: ISO 8601, unix seconds, a date (00:00 UTC) or relative (-14d)")
      ->required();
  cmd->add_option("--to", args->to, "end time, exclusive, in the same forms (default: now)");
  cmd->add_option("--table", args->table,
                  "1min (measurement_1min, default), 5s (sample_5s) or interval "
                  "(measurement_interval: imported data of a coarser logger, at its step)")
      ->check(CLI::IsMember({"1min", "5s", "interval"}));
  cmd->add_option("--out", args->out, "output CSV (default: standard output)");
  cmd->add_option("--db", args->db, "SQLite file to use instead of [storage] path");
  cmd->callback([args] { SetExitCode(RunExport(*args)); });
}

}  // namespace pvtwin::cli
