// Loading of the inputs shared by the data-driven subcommands (simulate,
// calibrate, backtest): config, CSV, variant. Each loader prints every problem
// to stderr as "file:line: field = value: rule" and returns false, and the
// caller exits with code 2.
#pragma once

#include <span>
#include <string>

#include "config/plant_config.h"
#include "core/common/series.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"
#include "io/platform/local_time.h"

namespace pvtwin::cli {

bool LoadConfigOrReport(const std::string& path, Config* config);
// A child of the daemon (calibration, diagnosis) dies with it: a kill -9 of
// the daemon must not leave a child running that writes where the next one
// reads. parent_pid <= 0: not a child, nothing to do. False (and a message)
// when the parent is already gone.
bool DieWithParent(int parent_pid);
bool LoadCsvOrReport(const std::string& path, const Config& config, Series* series,
                     const NaiveTimeZone* naive_time_zone = nullptr);
bool ParseVariantOrReport(const std::string& name, ModelSpec* spec);
// Drivers of `spec` for `series`; reports the missing columns naming the CSV.
bool PrepareDriversOrReport(const Series& series, const std::string& csv_path, const Config& config,
                            const ModelSpec& spec, Drivers* drivers);

// Parses a time given on the command line (ISO 8601 or unix seconds).
bool ParseTimeOrReport(const std::string& option, const std::string& text, std::int64_t* unix_s);

// Writes time and `channels` of `series` as canonical CSV to `out`, or to
// standard output when `out` is empty or "-". Reports a failure on stderr.
bool WriteCsvOrReport(const std::string& out, const Series& series,
                      std::span<const Channel> channels);

}  // namespace pvtwin::cli
