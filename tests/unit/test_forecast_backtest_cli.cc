// `pvtwin backtest --forecast` (core/forecast/forecast_backtest.h) on a plant
// the real `pvtwin sim` exports: every issued day is scored on its 1440
// minutes; with a weather-forecast file that is the truth plus a day-ahead
// error the forecast beats smart persistence, without one it does not; bad
// options are errors naming the option.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/files.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

using testing::RunPvtwin;
using testing::ScratchDir;

const std::string kConfig = std::string(PVTWIN_SOURCE_DIR) + "/config/examples/sim-plant.toml";

// The hourly means of the exported plant's weather as a canonical weather
// CSV, the irradiance times exp(ε) with ε an hourly AR(1) (ρ = 0.7, σ) and
// the air temperature plus an AR(1) of 4σ K: a day-ahead forecast's error.
void WriteWeatherForecast(const std::string& plant_csv, const std::string& out, double sigma) {
  std::ifstream in(plant_csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::stringstream h(line); std::getline(h, line, ',');) header.push_back(line);
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const std::vector<std::string> names = {"g_poa_w_m2", "ghi_w_m2", "dhi_w_m2", "t_amb_c",
                                          "wind_m_s"};
  std::ofstream csv(out);
  csv << "time,g_poa_w_m2,ghi_w_m2,dhi_w_m2,t_amb_c,wind_m_s\n";
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  double e_g = 0.0, e_t = 0.0;
  std::vector<double> sum(names.size(), 0.0);
  int n = 0;
  std::string hour;
  const auto flush = [&] {
    if (n == 0) return;
    e_g = 0.7 * e_g + std::sqrt(1 - 0.49) * sigma * normal(rng);
    e_t = 0.7 * e_t + std::sqrt(1 - 0.49) * 4 * sigma * normal(rng);
    csv << hour << ":00:00Z";
    for (std::size_t k = 0; k < names.size(); ++k) {
      const double mean = sum[k] / n;
      csv << "," << (k < 3 ? mean * std::exp(e_g) : (k == 3 ? mean + e_t : mean));
    }
    csv << "\n";
    std::fill(sum.begin(), sum.end(), 0.0);
    n = 0;
  };
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    for (std::stringstream c(line); std::getline(c, line, ',');) cells.push_back(line);
    const std::string this_hour = cells[0].substr(0, 13);
    if (this_hour != hour) {
      flush();
      hour = this_hour;
    }
    for (std::size_t k = 0; k < names.size(); ++k) sum[k] += std::stod(cells[column(names[k])]);
    ++n;
  }
  flush();
}

struct Totals {
  double skill_p = NAN, cover_p = NAN, skill_q = NAN, cover_q = NAN;
  int days = 0, full_days = 0;
};

Totals Parse(const std::string& out) {
  Totals t;
  static const std::regex kDay(R"(^\d{4}-\d\d-\d\dT\d\d:\d\dZ +\S+ \S+ +\d+ +(\d+) )");
  static const std::regex kAll(
      R"(all (\d+) days +\d+ +\d+ +[0-9.]+ W +(-?[0-9.]+) +([0-9.]+) +[0-9.]+ W +(-?[0-9.]+) +)"
      R"(([0-9.]+))");
  std::smatch m;
  std::stringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_search(line, m, kDay)) t.full_days += std::stoi(m[1]) == 1440;
    if (std::regex_search(line, m, kAll)) {
      t.days = std::stoi(m[1]);
      t.skill_p = std::stod(m[2]);
      t.cover_p = std::stod(m[3]);
      t.skill_q = std::stod(m[4]);
      t.cover_q = std::stod(m[5]);
    }
  }
  return t;
}

TEST(BacktestForecast, AWeatherForecastFileBeatsPersistenceAndEveryDayIsScored) {
  ScratchDir dir("fcbt");
  ASSERT_EQ(RunPvtwin(dir.path(), "sim --config '" + kConfig +
                                      "' --export plant.csv --days 22 --step 60 --start "
                                      "2024-06-01 --seed 5")
                .exit_code,
            0);
  WriteWeatherForecast((dir / "plant.csv").string(), (dir / "weather.csv").string(), 0.15);
  const std::string base = "backtest --forecast --config '" + kConfig +
                           "' --csv plant.csv --variants 2N1Ccolwr --test-days 6";
  const auto persisted = RunPvtwin(dir.path(), base);
  ASSERT_EQ(persisted.exit_code, 0) << persisted.err;
  const auto forecast = RunPvtwin(dir.path(), base + " --weather weather.csv");
  ASSERT_EQ(forecast.exit_code, 0) << forecast.err;
  const Totals p = Parse(persisted.out), f = Parse(forecast.out);
  EXPECT_EQ(p.days, 6) << persisted.out;
  EXPECT_EQ(p.full_days, 6) << persisted.out;
  EXPECT_EQ(f.days, 6) << forecast.out;
  EXPECT_LT(p.skill_p, 0.05) << persisted.out;
  EXPECT_GT(f.skill_p, 0.2) << forecast.out;
  EXPECT_GT(f.skill_q, p.skill_q) << forecast.out;
  for (double c : {p.cover_p, p.cover_q, f.cover_p, f.cover_q}) {
    EXPECT_GT(c, 0.6);
    EXPECT_LT(c, 0.97);
  }
  EXPECT_NE(forecast.err.find("weather forecast weather.csv (canonical CSV)"), std::string::npos)
      << forecast.err;
  EXPECT_NE(forecast.out.find("all days: MAE P_el "), std::string::npos);
}

TEST(BacktestForecast, BadOptionsAreErrorsNamingTheOption) {
  ScratchDir dir("fcbt_bad");
  ASSERT_EQ(RunPvtwin(dir.path(), "sim --config '" + kConfig +
                                      "' --export fine.csv --days 3 --step 5 --start 2024-06-01")
                .exit_code,
            0);
  const auto step = RunPvtwin(
      dir.path(), "backtest --forecast --config '" + kConfig + "' --csv fine.csv --train-days 2");
  EXPECT_EQ(step.exit_code, 2);
  EXPECT_NE(step.err.find("fine.csv: backtest --forecast needs 1-min rows"), std::string::npos)
      << step.err;
  ASSERT_EQ(RunPvtwin(dir.path(), "sim --config '" + kConfig +
                                      "' --export min.csv --days 3 --step 60 --start 2024-06-01")
                .exit_code,
            0);
  const auto at = RunPvtwin(dir.path(), "backtest --forecast --config '" + kConfig +
                                            "' --csv min.csv --train-days 2 --issue-at 25:00");
  EXPECT_EQ(at.exit_code, 2);
  EXPECT_NE(at.err.find("--issue-at = 25:00: expected HH:MM"), std::string::npos) << at.err;
  const auto weather =
      RunPvtwin(dir.path(), "backtest --forecast --config '" + kConfig +
                                "' --csv min.csv --train-days 2 --weather missing.json");
  EXPECT_EQ(weather.exit_code, 2);
  EXPECT_NE(weather.err.find("missing.json: cannot be read"), std::string::npos) << weather.err;
}

}  // namespace
}  // namespace pvtwin
