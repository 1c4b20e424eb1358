// What tests of forecast_skill compare it with: a day's row computed by the
// test in C++ from the stored rows (each measured row against the newest
// issue at or before the day began, weighted by its minutes, as
// doc/sql.md states the rule), rows of two queries compared cell by cell,
// and SQLite's own count of the work a query does.
#pragma once

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "core/common/series.h"
#include "io/store/store.h"
#include "tests/support/sqlite_db.h"

namespace pvtwin::testing {

// Measured rows of [from, to) at step_s: power that follows the sun's hours
// with a wobble, every 7th row (every 97th at 1 min) invalid.
inline Series Measured(std::int64_t from, std::int64_t to, int step_s, double offset_w) {
  constexpr std::int64_t kDayS = 86400;
  Series s;
  s.step_s = step_s;
  std::vector<double> p_el_w, q_th_w, valid;
  for (std::int64_t t = from; t < to; t += step_s) {
    const double h = static_cast<double>(t % kDayS) / 3600.0;
    const double sun = std::max(0.0, std::sin((h - 6.0) / 12.0 * M_PI));
    const auto x = static_cast<double>(t);
    s.time_s.push_back(t);
    p_el_w.push_back(offset_w + 400.0 * sun + 30.0 * std::sin(x / 700.0));
    q_th_w.push_back(offset_w + 1200.0 * sun - 80.0 + 50.0 * std::cos(x / 900.0));
    valid.push_back((t / step_s) % (step_s == 60 ? 97 : 7) == 0 ? 0.0 : 1.0);
  }
  s[Channel::kPElW] = p_el_w;
  s[Channel::kQThW] = q_th_w;
  s[Channel::kValid] = valid;
  return s;
}

// One issue at issued_at for [issued_at, issued_at + horizon_s) at 1 min,
// with bands, medians and the reference, on a half-sine day; `bias` shifts
// its values.
inline std::vector<Store::ForecastRow> Issue(std::int64_t issued_at, std::int64_t horizon_s,
                                             double bias) {
  constexpr std::int64_t kDayS = 86400;
  std::vector<Store::ForecastRow> rows;
  for (std::int64_t t = issued_at; t < issued_at + horizon_s; t += 60) {
    const double h = static_cast<double>(t % kDayS) / 3600.0;
    const double sun = std::max(0.0, std::sin((h - 6.0) / 12.0 * M_PI));
    Store::ForecastRow r;
    r.ts = t;
    r.p_el_w = 390.0 * sun + bias;
    r.q_th_w = 1150.0 * sun - 70.0 + 0.5 * bias;
    r.p_el_w_p10 = r.p_el_w - 25.0;
    r.p_el_w_p90 = r.p_el_w + 20.0;
    r.q_th_w_p10 = r.q_th_w - 60.0;
    r.q_th_w_p90 = r.q_th_w + 40.0;
    r.p_el_w_p50 = r.p_el_w;
    r.q_th_w_p50 = r.q_th_w;
    r.p_el_w_ref = 350.0 * sun;
    r.q_th_w_ref = 1000.0 * sun;
    rows.push_back(r);
  }
  return rows;
}

// SQLite's counters of one query run to its end on its own connection.
struct QueryCost {
  long vm_steps = 0;        // SQLITE_STMTSTATUS_VM_STEP
  long fullscan_steps = 0;  // SQLITE_STMTSTATUS_FULLSCAN_STEP
  long rows = 0;
};

inline QueryCost CostOf(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  QueryCost cost;
  EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK)
      << sql << ": " << sqlite3_errmsg(db);
  while (stmt != nullptr && sqlite3_step(stmt) == SQLITE_ROW) ++cost.rows;
  cost.vm_steps = sqlite3_stmt_status(stmt, SQLITE_STMTSTATUS_VM_STEP, 0);
  cost.fullscan_steps = sqlite3_stmt_status(stmt, SQLITE_STMTSTATUS_FULLSCAN_STEP, 0);
  sqlite3_finalize(stmt);
  sqlite3_close_v2(db);
  return cost;
}

using Rows = std::vector<std::vector<std::string>>;

// Rows of two queries are equal: the same days and NULLs, integers exactly,
// reals to `relative` (a sum's order may differ between whole-table and
// per-day aggregation, and between SQL and C++).
inline void ExpectSameRows(const Rows& actual, const Rows& expected, const std::string& what,
                           double relative = 1e-12) {
  ASSERT_EQ(actual.size(), expected.size()) << what;
  for (std::size_t r = 0; r < actual.size(); ++r) {
    ASSERT_EQ(actual[r].size(), expected[r].size()) << what;
    for (std::size_t c = 0; c < actual[r].size(); ++c) {
      const std::string& a = actual[r][c];
      const std::string& e = expected[r][c];
      if (a == e) continue;
      ASSERT_NE(a, "NULL") << what << " row " << r << " column " << c << ": expected " << e;
      ASSERT_NE(e, "NULL") << what << " row " << r << " column " << c << ": got " << a;
      const double x = std::strtod(a.c_str(), nullptr), y = std::strtod(e.c_str(), nullptr);
      EXPECT_LE(std::abs(x - y), relative * std::max(1.0, std::abs(y)))
          << what << " day " << actual[r][0] << " column " << c << ": " << a << " vs " << e;
    }
  }
}

// One day of forecast_skill computed by the test: the columns after `day`,
// NaN for NULL, and the pairs it scored.
struct SkillByHand {
  double mae_p_el_w = NAN, mae_q_th_w = NAN, nmae_p_el = NAN, nmae_q_th = NAN;
  double skill_p_el = NAN, skill_q_th = NAN, coverage_p10_p90 = NAN, minutes = 0.0;
  double coverage_p_el = NAN, coverage_q_th = NAN;
  int pairs = 0;
  // As the view's row would read after `day` (a cell per column).
  std::vector<std::string> Cells(const std::string& day) const {
    std::vector<std::string> cells = {day};
    for (const double x : {mae_p_el_w, mae_q_th_w, nmae_p_el, nmae_q_th, skill_p_el, skill_q_th,
                           coverage_p10_p90, minutes, coverage_p_el, coverage_q_th}) {
      char text[64];
      std::snprintf(text, sizeof text, "%.17g", x);
      cells.push_back(std::isnan(x) ? "NULL" : text);
    }
    return cells;
  }
};

namespace skill_detail {
inline double Cell(const std::string& text) {
  return text == "NULL" ? NAN : std::strtod(text.c_str(), nullptr);
}
// Sums of one output over a day's pairs, each weighted by its minutes w.
struct Sums {
  double err = 0, err_w = 0, meas = 0;  // w|f - m|, w, w|m| where both are known
  double err_with_ref = 0, ref = 0;     // w|f - m|, w|ref - m| where all three are
  double inside = 0, banded = 0;        // w where m lies in a band of width, w banded
  bool with_ref = false;
  void Add(double w, double m, double f, double ref_f, double p10, double p90) {
    if (!std::isnan(f) && !std::isnan(m)) {
      err += w * std::abs(f - m);
      err_w += w;
      meas += w * std::abs(m);
      if (!std::isnan(ref_f)) {
        err_with_ref += w * std::abs(f - m);
        ref += w * std::abs(ref_f - m);
        with_ref = true;
      }
    }
    if (p90 > p10 && !std::isnan(m)) {
      banded += w;
      inside += (m >= p10 && m <= p90) ? w : 0.0;
    }
  }
};
}  // namespace skill_detail

// The day [start, end) of `table` (measurement_1min or measurement_interval)
// scored by hand: each row with valid not 0 against the forecast row at its
// ts of the newest issue at or before `cutoff`, weighted by step_s / 60
// (60 s for a 1-min row); skill and coverage from 360 scored minutes on.
inline SkillByHand ScoreDayByHand(RawDb& db, const std::string& table, std::int64_t start,
                                  std::int64_t end, std::int64_t cutoff) {
  using skill_detail::Cell;
  const std::string range =
      " WHERE ts >= " + std::to_string(start) + " AND ts < " + std::to_string(end);
  // ts -> (issued_at, columns) of the newest qualifying issue.
  std::map<std::int64_t, std::pair<std::int64_t, std::vector<std::string>>> forecast;
  for (const auto& row : db.Rows("SELECT ts, issued_at, p_el_w, q_th_w, p_el_w_p10, p_el_w_p90, "
                                 "q_th_w_p10, q_th_w_p90, p_el_w_ref, q_th_w_ref FROM forecast" +
                                 range)) {
    const std::int64_t ts = std::stoll(row[0]), issued = std::stoll(row[1]);
    if (issued > cutoff) continue;
    auto it = forecast.find(ts);
    if (it == forecast.end() || it->second.first < issued) forecast[ts] = {issued, row};
  }
  const std::string step = table == "measurement_1min" ? "60" : "step_s";
  skill_detail::Sums p, q;
  SkillByHand day;
  for (const auto& m :
       db.Rows("SELECT ts, " + step + ", p_el_w, q_th_w, valid FROM " + table + range)) {
    if (m[4] != "NULL" && Cell(m[4]) == 0.0) continue;
    const auto it = forecast.find(std::stoll(m[0]));
    if (it == forecast.end()) continue;
    const std::vector<std::string>& f = it->second.second;
    const double w = Cell(m[1]) / 60.0;
    p.Add(w, Cell(m[2]), Cell(f[2]), Cell(f[8]), Cell(f[4]), Cell(f[5]));
    q.Add(w, Cell(m[3]), Cell(f[3]), Cell(f[9]), Cell(f[6]), Cell(f[7]));
    day.minutes += w;
    ++day.pairs;
  }
  const auto mae = [](const skill_detail::Sums& s) { return s.err_w > 0 ? s.err / s.err_w : NAN; };
  day.mae_p_el_w = mae(p);
  day.mae_q_th_w = mae(q);
  const auto nmae = [](const skill_detail::Sums& s) {
    return s.err_w > 0 && s.meas > 0 ? s.err / s.meas : NAN;
  };
  day.nmae_p_el = nmae(p);
  day.nmae_q_th = nmae(q);
  if (day.minutes >= 360.0) {
    const auto skill = [](const skill_detail::Sums& s) {
      return s.with_ref && s.ref > 0 ? 1.0 - s.err_with_ref / s.ref : NAN;
    };
    day.skill_p_el = skill(p);
    day.skill_q_th = skill(q);
    const auto share = [](double inside, double banded) {
      return banded > 0 ? inside / banded : NAN;
    };
    day.coverage_p10_p90 = share(p.inside + q.inside, p.banded + q.banded);
    day.coverage_p_el = share(p.inside, p.banded);
    day.coverage_q_th = share(q.inside, q.banded);
  }
  return day;
}

// Hourly issues from `from` to `to` (exclusive), each 26 h ahead with a
// bias that wanders with the issue time.
inline void InsertHourlyIssues(Store* store, std::int64_t from, std::int64_t to) {
  std::string error;
  for (std::int64_t issued = from; issued < to; issued += 3600) {
    const double bias = 10.0 * std::sin(static_cast<double>(issued) / 5000.0);
    ASSERT_TRUE(store->InsertForecast(issued, 0, "test", Issue(issued, 26 * 3600, bias), &error))
        << error;
  }
}

}  // namespace pvtwin::testing
