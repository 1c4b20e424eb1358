// The store's measurements and forecast inputs: 5 s samples, their
// aggregation into 1-min rows, imported 1-min and interval rows, retention,
// the weather forecast and operation plan tables and the plant's
// configuration (io/store/store.h).
#include <sqlite3.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/data/physical_limits.h"
#include "io/store/store_impl.h"

namespace pvtwin {

using namespace store_detail;

namespace {

// Drops the columns that are NaN in every row.
void DropEmptyColumns(Series* s) {
  for (auto& col : s->columns) {
    if (std::all_of(col.begin(), col.end(), [](double x) { return std::isnan(x); })) col.clear();
  }
}

const std::string& SelectSamplesSql() {
  static const std::string sql = "SELECT ts, " + ChannelColumns() +
                                 ", rejected_mask FROM sample_5s WHERE ts >= ? AND ts < ? "
                                 "ORDER BY ts";
  return sql;
}

void ReadSampleRow(sqlite3_stmt* stmt, Sample* s) {
  s->ts_s = sqlite3_column_int64(stmt, 0);
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    s->value[c] = FromSql(static_cast<Channel>(c), ColumnReal(stmt, static_cast<int>(c) + 1));
  }
  s->rejected_mask =
      static_cast<std::uint32_t>(sqlite3_column_int64(stmt, static_cast<int>(kNumChannels) + 1));
}

// qc_flags of an imported row: kQcImported, a bit per missing channel and
// kQcRequiredMissing when a required one is among them.
std::uint32_t ImportedRowFlags(const Series& rows, std::size_t i) {
  std::uint32_t f = kQcImported;
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    const auto channel = static_cast<Channel>(c);
    if (channel != Channel::kValid && std::isnan(rows.At(channel, i))) {
      f |= QcChannelMissingBit(channel);
    }
  }
  if (!RequiredChannelsPresent(f)) f |= kQcRequiredMissing;
  return f;
}

}  // namespace

bool Store::InsertSamples(const std::vector<Sample>& batch, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  static const std::string sql = "INSERT OR REPLACE INTO sample_5s(ts, " + ChannelColumns() +
                                 ", rejected_mask) VALUES(" + Placeholders(kNumChannels + 2) + ")";
  const bool ok = db.Run(
      true, "insert " + std::to_string(batch.size()) + " samples",
      [&db, &batch]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(sql, &stmt);
        if (!s.ok()) return s;
        for (const Sample& sample : batch) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, sample.ts_s);
          for (std::size_t c = 0; c < kNumChannels; ++c) {
            BindReal(stmt, static_cast<int>(c) + 2,
                     ToSql(static_cast<Channel>(c), sample.value[c]));
          }
          sqlite3_bind_int64(stmt, static_cast<int>(kNumChannels) + 2, sample.rejected_mask);
          s = db.StepDone(stmt, "insert sample ts " + std::to_string(sample.ts_s));
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
  if (ok) {
    for (const Sample& sample : batch) {
      db.aggregate_scan_from = std::min(db.aggregate_scan_from, MinuteStart(sample.ts_s));
    }
  }
  return ok;
}

bool Store::ReadSamples(std::int64_t from_ts, std::int64_t to_ts, std::vector<Sample>* out,
                        std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<Sample> samples;
  const bool ok = db.Run(
      false, "read samples",
      [&]() -> DbStatus {
        samples.clear();
        return db.SelectRange(
            SelectSamplesSql(), from_ts, to_ts,
            [&samples](sqlite3_stmt* stmt) { ReadSampleRow(stmt, &samples.emplace_back()); },
            "read samples");
      },
      error);
  if (ok) *out = std::move(samples);
  return ok;
}

DbStatus Store::Impl::WriteMinuteRows(const MinuteRows& minutes, bool replace, bool imported) {
  Impl& db = *this;
  static const std::string tail = " INTO measurement_1min(ts, " + ChannelColumns() +
                                  ", n_samples, qc_flags) VALUES(" +
                                  Placeholders(kNumChannels + 3) + ")";
  static const std::string insert_sql = "INSERT" + tail;
  static const std::string replace_sql = "INSERT OR REPLACE" + tail;
  sqlite3_stmt* stmt = nullptr;
  DbStatus s = db.Prepare(replace ? replace_sql : insert_sql, &stmt);
  if (!s.ok()) return s;
  const Series& rows = minutes.rows;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    sqlite3_reset(stmt);
    sqlite3_bind_int64(stmt, 1, rows.time_s[i]);
    for (std::size_t c = 0; c < kNumChannels; ++c) {
      const auto channel = static_cast<Channel>(c);
      BindReal(stmt, static_cast<int>(c) + 2, ToSql(channel, rows.At(channel, i)));
    }
    const int n_index = static_cast<int>(kNumChannels) + 2;
    if (imported) {
      sqlite3_bind_null(stmt, n_index);
    } else {
      sqlite3_bind_int(stmt, n_index, minutes.n_samples[i]);
    }
    sqlite3_bind_int64(stmt, n_index + 1, minutes.qc_flags[i]);
    s = db.StepDone(stmt, "write 1-min row ts " + std::to_string(rows.time_s[i]));
    if (!s.ok()) return s;
  }
  if (rows.size() == 0) return {};
  const auto [first, last] = std::minmax_element(rows.time_s.begin(), rows.time_s.end());
  return db.CoverLocalDays(*first, *last + kMinuteS);
}

DbStatus Store::Impl::AggregateRange(std::int64_t from_ts, std::int64_t to_ts, bool all,
                                     int* minutes_written) {
  Impl& db = *this;
  static const std::string pending_sql =
      "SELECT s.ts, " + ChannelColumns("s.") +
      ", s.rejected_mask FROM sample_5s s WHERE s.ts >= ? AND s.ts < ? AND NOT EXISTS ("
      "SELECT 1 FROM measurement_1min m WHERE m.ts = s.ts - ((s.ts % 60) + 60) % 60) "
      "ORDER BY s.ts";
  std::vector<Sample> samples;
  DbStatus s = db.SelectRange(
      all ? SelectSamplesSql() : pending_sql, from_ts, to_ts,
      [&samples](sqlite3_stmt* stmt) { ReadSampleRow(stmt, &samples.emplace_back()); },
      "read samples to aggregate");
  if (!s.ok()) return s;
  MinuteRows minutes;
  std::string error;
  if (!AggregateSamples(samples, db.options.aggregate, &minutes, &error)) {
    return {SQLITE_ERROR, "aggregate", error};
  }
  s = WriteMinuteRows(minutes, all, false);
  if (s.ok()) *minutes_written = static_cast<int>(minutes.rows.size());
  return s;
}

bool Store::AggregateMinutes(std::int64_t up_to_ts, int* minutes_written, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  const std::int64_t end_ts = MinuteStart(up_to_ts);  // minutes before it are complete
  int written = 0;
  const bool ok = db.Run(
      true, "aggregate minutes",
      [&] { return db.AggregateRange(db.aggregate_scan_from, end_ts, false, &written); }, error);
  if (ok) db.aggregate_scan_from = std::max(db.aggregate_scan_from, end_ts);
  if (minutes_written != nullptr) *minutes_written = ok ? written : 0;
  return ok;
}

bool Store::ReaggregateMinutes(std::int64_t from_ts, std::int64_t to_ts, int* minutes_written,
                               std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  const std::int64_t begin = MinuteStart(from_ts);
  const std::int64_t end = MinuteStart(to_ts) + (to_ts == MinuteStart(to_ts) ? 0 : kMinuteS);
  int written = 0;
  const bool ok = db.Run(
      true, "re-aggregate minutes", [&] { return db.AggregateRange(begin, end, true, &written); },
      error);
  if (minutes_written != nullptr) *minutes_written = ok ? written : 0;
  return ok;
}

bool Store::WriteMinutes(const Series& rows_1min, std::string* error) {
  MinuteRows minutes;
  minutes.rows = rows_1min;
  minutes.n_samples.assign(rows_1min.size(), 0);
  minutes.qc_flags.assign(rows_1min.size(), kQcImported);
  for (std::size_t i = 0; i < rows_1min.size(); ++i) {
    if (rows_1min.time_s[i] != MinuteStart(rows_1min.time_s[i])) {
      *error = impl_->path + ": 1-min row " + std::to_string(i) + " at ts " +
               std::to_string(rows_1min.time_s[i]) + ": not the start of a minute";
      return false;
    }
    minutes.qc_flags[i] = ImportedRowFlags(rows_1min, i);
  }
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write " + std::to_string(rows_1min.size()) + " 1-min rows",
      [&] { return db.WriteMinuteRows(minutes, true, true); }, error);
}

bool Store::ReadMinuteRows(std::int64_t from_ts, std::int64_t to_ts, MinuteRows* out,
                           std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  static const std::string sql = "SELECT ts, " + ChannelColumns() +
                                 ", n_samples, qc_flags FROM measurement_1min "
                                 "WHERE ts >= ? AND ts < ? ORDER BY ts";
  MinuteRows result;
  const bool ok = db.Run(
      false, "read 1-min rows",
      [&]() -> DbStatus {
        result = MinuteRows{};
        Series& rows = result.rows;
        rows.step_s = static_cast<double>(kMinuteS);
        auto on_row = [&result, &rows](sqlite3_stmt* stmt) {
          rows.time_s.push_back(sqlite3_column_int64(stmt, 0));
          for (std::size_t c = 0; c < kNumChannels; ++c) {
            rows.columns[c].push_back(
                FromSql(static_cast<Channel>(c), ColumnReal(stmt, static_cast<int>(c) + 1)));
          }
          const int n_index = static_cast<int>(kNumChannels) + 1;
          result.n_samples.push_back(sqlite3_column_int(stmt, n_index));
          result.qc_flags.push_back(
              static_cast<std::uint32_t>(sqlite3_column_int64(stmt, n_index + 1)));
        };
        return db.SelectRange(sql, from_ts, to_ts, on_row, "read 1-min rows");
      },
      error);
  if (!ok) return false;
  // Rows written by other programs (SQL) pass the physical limits too.
  ApplyPhysicalLimits(&result.rows, db.options.aggregate.area_m2);
  DropEmptyColumns(&result.rows);
  *out = std::move(result);
  return true;
}

bool Store::WriteIntervalRows(const Series& rows, std::string* error) {
  const auto step_s = static_cast<std::int64_t>(rows.step_s);
  if (static_cast<double>(step_s) != rows.step_s || step_s <= kMinuteS || step_s % kMinuteS != 0) {
    *error = impl_->path + ": measurement_interval: step " + std::to_string(rows.step_s) +
             " s is not a whole number of minutes above one";
    return false;
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows.time_s[i] != MinuteStart(rows.time_s[i])) {
      *error = impl_->path + ": interval row " + std::to_string(i) + " at ts " +
               std::to_string(rows.time_s[i]) + ": not the start of a minute";
      return false;
    }
  }
  static const std::string sql = "INSERT OR REPLACE INTO measurement_interval(ts, step_s, " +
                                 ChannelColumns() + ", qc_flags) VALUES(" +
                                 Placeholders(kNumChannels + 3) + ")";
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write " + std::to_string(rows.size()) + " interval rows",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(sql, &stmt);
        if (!s.ok()) return s;
        for (std::size_t i = 0; i < rows.size(); ++i) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, rows.time_s[i]);
          sqlite3_bind_int64(stmt, 2, step_s);
          for (std::size_t c = 0; c < kNumChannels; ++c) {
            const auto channel = static_cast<Channel>(c);
            BindReal(stmt, static_cast<int>(c) + 3, ToSql(channel, rows.At(channel, i)));
          }
          sqlite3_bind_int64(stmt, static_cast<int>(kNumChannels) + 3, ImportedRowFlags(rows, i));
          s = db.StepDone(stmt, "write interval row ts " + std::to_string(rows.time_s[i]));
          if (!s.ok()) return s;
        }
        if (rows.size() == 0) return DbStatus{};
        const auto range = std::minmax_element(rows.time_s.begin(), rows.time_s.end());
        return db.CoverLocalDays(*range.first, *range.second + step_s);
      },
      error);
}

bool Store::ReadIntervalRows(std::int64_t from_ts, std::int64_t to_ts, Series* out,
                             std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  static const std::string sql = "SELECT ts, step_s, " + ChannelColumns() +
                                 " FROM measurement_interval WHERE ts >= ? AND ts < ? ORDER BY ts";
  Series rows;
  std::map<std::int64_t, std::size_t> steps;  // step_s -> rows
  const bool ok = db.Run(
      false, "read interval rows",
      [&]() -> DbStatus {
        rows = Series{};
        steps.clear();
        return db.SelectRange(
            sql, from_ts, to_ts,
            [&rows, &steps](sqlite3_stmt* stmt) {
              rows.time_s.push_back(sqlite3_column_int64(stmt, 0));
              ++steps[sqlite3_column_int64(stmt, 1)];
              for (std::size_t c = 0; c < kNumChannels; ++c) {
                rows.columns[c].push_back(
                    FromSql(static_cast<Channel>(c), ColumnReal(stmt, static_cast<int>(c) + 2)));
              }
            },
            "read interval rows");
      },
      error);
  if (!ok) return false;
  rows.step_s = static_cast<double>(kMinuteS);
  std::size_t most = 0;
  for (const auto& [step_s, n] : steps) {
    if (n > most) {
      most = n;
      rows.step_s = static_cast<double>(step_s);
    }
  }
  ApplyPhysicalLimits(&rows, db.options.aggregate.area_m2);
  DropEmptyColumns(&rows);
  *out = std::move(rows);
  return true;
}

bool Store::ReadMinutes(std::int64_t from_ts, std::int64_t to_ts, Series* out, std::string* error) {
  MinuteRows rows;
  if (!ReadMinuteRows(from_ts, to_ts, &rows, error)) return false;
  *out = std::move(rows.rows);
  return true;
}

bool Store::ApplyRetention(std::int64_t now_ts, int raw_retention_days, std::string* error) {
  Impl& db = *impl_;
  if (raw_retention_days < 1) {
    *error = "raw_retention_days = " + std::to_string(raw_retention_days) + ": must be >= 1";
    return false;
  }
  std::lock_guard lock(db.mutex);
  const std::int64_t cutoff_ts = MinuteStart(now_ts - raw_retention_days * kSecondsPerDay);
  return db.Run(
      true, "apply retention",
      [&]() -> DbStatus {
        int written = 0;
        DbStatus s = db.AggregateRange(kNoLowerBound, cutoff_ts, false, &written);
        if (!s.ok()) return s;
        sqlite3_stmt* stmt = nullptr;
        s = db.Prepare("DELETE FROM sample_5s WHERE ts < ?", &stmt);
        if (!s.ok()) return s;
        sqlite3_bind_int64(stmt, 1, cutoff_ts);
        s = db.StepDone(stmt, "delete samples before " + std::to_string(cutoff_ts));
        if (!s.ok()) return s;
        // A week back: rows before that were pruned by earlier daily calls,
        // and the DELETE stays short while it holds the write lock.
        return db.PruneForecasts(cutoff_ts - 7 * kSecondsPerDay, cutoff_ts);
      },
      error);
}

namespace {

// A forecast input cell: NULL is missing; INTEGER and REAL are numbers; TEXT
// and BLOB (which sqlite3_column_double would turn into 0, or into the
// number a text starts with) are missing unless the whole text, blanks
// around it aside, is a finite decimal number. *text is set for a cell read
// as missing because it held text.
double InputCell(sqlite3_stmt* stmt, int index, bool* text) {
  *text = false;
  const int type = sqlite3_column_type(stmt, index);
  if (type == SQLITE_NULL) return std::nan("");
  if (type != SQLITE_TEXT && type != SQLITE_BLOB) return sqlite3_column_double(stmt, index);
  const auto* chars = reinterpret_cast<const char*>(sqlite3_column_text(stmt, index));
  std::string cell(chars == nullptr ? "" : chars,
                   static_cast<std::size_t>(sqlite3_column_bytes(stmt, index)));
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!cell.empty() && blank(cell.back())) cell.pop_back();
  std::size_t first = 0;
  while (first < cell.size() && blank(cell[first])) ++first;
  cell.erase(0, first);
  // Decimal digits, sign, point and exponent only: no hex, inf or nan,
  // which strtod would also take.
  const bool decimal =
      !cell.empty() && cell.find_first_not_of("0123456789+-.eE") == std::string::npos;
  char* end = nullptr;
  const double value = decimal ? std::strtod(cell.c_str(), &end) : 0.0;
  if (decimal && end == cell.c_str() + cell.size() && std::isfinite(value)) return value;
  *text = true;
  return std::nan("");
}

}  // namespace

std::size_t Store::TextCells::Total() const {
  std::size_t total = 0;
  for (const std::size_t n : count) total += n;
  return total;
}

std::string Store::TextCells::Warning(const std::string& table) const {
  std::string list;
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    if (count[c] == 0) continue;
    list += list.empty() ? std::to_string(count[c]) + " cells of "
                         : ", " + std::to_string(count[c]) + " of ";
    list += std::string(ChannelName(static_cast<Channel>(c)));
  }
  return list.empty() ? "" : table + ": " + list + " hold text, read as missing";
}

bool Store::Impl::ReadInputTable(const std::string& table, std::span<const Channel> channels,
                                 std::int64_t from, std::int64_t to, Series* out,
                                 std::string* error, TextCells* text_cells) {
  Impl& db = *this;
  std::string sql = "SELECT ts";
  for (const Channel c : channels) sql += ", " + std::string(ChannelName(c));
  sql += " FROM " + table + " WHERE ts >= ? AND ts < ? ORDER BY ts";
  Series result;
  TextCells texts;
  const bool ok = db.Run(
      false, "read " + table,
      [&]() -> DbStatus {
        result = Series{};
        texts = TextCells{};
        auto on_row = [&result, &texts, channels](sqlite3_stmt* stmt) {
          result.time_s.push_back(sqlite3_column_int64(stmt, 0));
          for (std::size_t k = 0; k < channels.size(); ++k) {
            bool text = false;
            const double value = InputCell(stmt, static_cast<int>(k) + 1, &text);
            texts.count[static_cast<std::size_t>(channels[k])] += text ? 1 : 0;
            result[channels[k]].push_back(FromSql(channels[k], value));
          }
        };
        return db.SelectRange(sql, from, to, on_row, "read " + table);
      },
      error);
  if (!ok) return false;
  if (text_cells != nullptr) *text_cells = texts;
  ApplyPhysicalLimits(&result, options.aggregate.area_m2);
  DropEmptyColumns(&result);
  result.step_s = 0.0;
  for (std::size_t i = 1; i < result.size(); ++i) {
    const auto dt_s = static_cast<double>(result.time_s[i] - result.time_s[i - 1]);
    if (result.step_s == 0.0 || dt_s < result.step_s) result.step_s = dt_s;
  }
  *out = std::move(result);
  return true;
}

bool Store::ReadWeatherForecast(std::int64_t from, std::int64_t to, Series* out, std::string* error,
                                TextCells* text_cells) {
  std::lock_guard lock(impl_->mutex);
  return impl_->ReadInputTable("weather_forecast", kWeatherChannels, from, to, out, error,
                               text_cells);
}

bool Store::ReadOperationPlan(std::int64_t from, std::int64_t to, Series* out, std::string* error,
                              TextCells* text_cells) {
  std::lock_guard lock(impl_->mutex);
  return impl_->ReadInputTable("operation_plan", kOperationChannels, from, to, out, error,
                               text_cells);
}

bool Store::WriteWeatherForecast(const Series& rows, const std::string& source,
                                 std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::string sql = "INSERT OR REPLACE INTO weather_forecast(ts";
  for (const Channel c : kWeatherChannels) sql += ", " + std::string(ChannelName(c));
  sql += ", source) VALUES(" + Placeholders(std::size(kWeatherChannels) + 2) + ")";
  return db.Run(
      true, "write weather_forecast",
      [&]() -> DbStatus {
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare(sql, &stmt);
        if (!s.ok()) return s;
        for (std::size_t i = 0; i < rows.size(); ++i) {
          sqlite3_reset(stmt);
          sqlite3_bind_int64(stmt, 1, rows.time_s[i]);
          int k = 2;
          for (const Channel c : kWeatherChannels) BindReal(stmt, k++, ToSql(c, rows.At(c, i)));
          sqlite3_bind_text(stmt, k, source.c_str(), -1, SQLITE_TRANSIENT);
          s = db.StepDone(stmt, "write weather_forecast ts " + std::to_string(rows.time_s[i]));
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
}

bool Store::ReadWeatherSources(std::int64_t from, std::int64_t to,
                               std::vector<std::string>* sources, std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<std::string> result;
  const bool ok = db.Run(
      false, "read weather_forecast sources",
      [&]() -> DbStatus {
        result.clear();
        return db.SelectRange(
            "SELECT COALESCE(source, 'weather_forecast') FROM weather_forecast WHERE ts >= ? AND "
            "ts < ? GROUP BY 1 ORDER BY COUNT(*) DESC, 1",
            from, to, [&](sqlite3_stmt* stmt) { result.push_back(ColumnText(stmt, 0)); },
            "read weather_forecast sources");
      },
      error);
  if (ok) *sources = std::move(result);
  return ok;
}

bool Store::WritePlantConfig(const std::vector<std::pair<std::string, double>>& values,
                             std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  return db.Run(
      true, "write plant_config",
      [&]() -> DbStatus {
        DbStatus s = db.Exec("DELETE FROM plant_config");
        if (!s.ok()) return s;
        sqlite3_stmt* stmt = nullptr;
        s = db.Prepare("INSERT INTO plant_config(key, value) VALUES(?, ?)", &stmt);
        if (!s.ok()) return s;
        for (const auto& [key, value] : values) {
          sqlite3_reset(stmt);
          sqlite3_bind_text(stmt, 1, key.c_str(), -1, SQLITE_TRANSIENT);
          sqlite3_bind_double(stmt, 2, value);
          s = db.StepDone(stmt, "write plant_config " + key);
          if (!s.ok()) return s;
        }
        return {};
      },
      error);
}

bool Store::ReadPlantConfig(std::vector<std::pair<std::string, double>>* values,
                            std::string* error) {
  Impl& db = *impl_;
  std::lock_guard lock(db.mutex);
  std::vector<std::pair<std::string, double>> result;
  const bool ok = db.Run(
      false, "read plant_config",
      [&]() -> DbStatus {
        result.clear();
        sqlite3_stmt* stmt = nullptr;
        DbStatus s = db.Prepare("SELECT key, value FROM plant_config ORDER BY key", &stmt);
        if (!s.ok()) return s;
        int rc;
        while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
          result.emplace_back(ColumnText(stmt, 0), sqlite3_column_double(stmt, 1));
        }
        sqlite3_reset(stmt);
        return rc == SQLITE_DONE ? DbStatus{} : db.Fail(rc, "read plant_config");
      },
      error);
  if (ok) *values = std::move(result);
  return ok;
}

}  // namespace pvtwin
