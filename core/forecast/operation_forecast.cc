#include "core/forecast/operation_forecast.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/common/units.h"
#include "core/forecast/forecast_bands.h"

namespace pvtwin {

namespace {

constexpr double kGridStepWM2 = 25.0;
constexpr double kGridMaxWM2 = 800.0;
constexpr double kMinSpanS = 86400.0;     // rows of a day (1440 minutes, 96 15-min rows)
constexpr std::size_t kMinHourRows = 10;   // on-rows an hour needs for its own flow
constexpr std::int64_t kMaxRowGapS = 600;  // a longer gap (or row step) restarts the rule's state
constexpr double kOnShareOfMedian = 0.1;   // flow above this share of the median is "on"

struct Row {
  std::int64_t t;
  double g, hour;
  bool on;
};

// Minutes the hysteresis rule (g_on, g_off) classifies right, of the rows
// inside the rule's hours (outside them it is off).
// A gap is longer than max_gap_s (kMaxRowGapS, or one row of a coarser
// step: consecutive 15-min rows are no gap).
std::size_t Matches(const std::vector<Row>& rows, double g_on, double g_off,
                    std::int64_t max_gap_s) {
  std::size_t right = 0;
  bool state = false;
  std::int64_t previous = std::numeric_limits<std::int64_t>::min() / 2;
  for (const Row& r : rows) {
    if (r.t - previous > max_gap_s) state = r.on;  // a gap: start from what was measured
    previous = r.t;
    state = state ? r.g >= g_off : r.g >= g_on;
    right += state == r.on ? 1 : 0;
  }
  return right;
}

}  // namespace

double SolarHour(const Plant& plant, std::int64_t time_s) {
  const double utc_h = static_cast<double>(((time_s % 86400) + 86400) % 86400) / 3600.0;
  return std::fmod(utc_h + plant.longitude_rad * 12.0 / kPi + 48.0, 24.0);
}

std::string PumpRule::Describe() const {
  if (!valid) return "no pump rule (too little data in the window)";
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "pump on at %s >= %.0f W/m2, off below %.0f W/m2, between %.1f and %.1f h solar "
                "time (%.1f %% of the window's minutes right)",
                on_plane ? "g_poa" : "ghi", g_on_w_m2, g_off_w_m2, first_hour, last_hour,
                100.0 * accuracy);
  return buf;
}

PumpRule LearnPumpRule(const Plant& plant, const Series& history) {
  PumpRule rule;
  rule.on_plane = history.Has(Channel::kGPoaWM2);
  const Channel g_channel = rule.on_plane ? Channel::kGPoaWM2 : Channel::kGhiWM2;
  if (!history.Has(Channel::kMdotKgS) || !history.Has(g_channel)) return rule;
  std::vector<double> positive;
  for (double f : history[Channel::kMdotKgS]) {
    if (std::isfinite(f) && f > 0.0) positive.push_back(f);
  }
  if (positive.empty()) return rule;
  const double threshold = kOnShareOfMedian * SampleQuantile(&positive, 0.5);
  std::vector<Row> rows;
  std::vector<double> on_hours;
  std::vector<std::vector<double>> flow_by_hour(24);
  for (std::size_t i = 0; i < history.size(); ++i) {
    const double f = history[Channel::kMdotKgS][i], g = history[g_channel][i];
    if (!std::isfinite(f) || !std::isfinite(g)) continue;
    const Row r{history.time_s[i], g, SolarHour(plant, history.time_s[i]), f > threshold};
    rows.push_back(r);
    if (!r.on) continue;
    on_hours.push_back(r.hour);
    flow_by_hour[static_cast<std::size_t>(r.hour) % 24].push_back(f);
  }
  // A day of rows at the history's step (interval rows of a coarser logger
  // count as the minutes they cover).
  const double step_s = history.step_s > 0.0 ? history.step_s : 60.0;
  const auto min_rows = static_cast<std::size_t>(std::lround(kMinSpanS / step_s));
  const std::int64_t max_gap_s = std::max<std::int64_t>(kMaxRowGapS, std::llround(step_s));
  if (rows.size() < min_rows || on_hours.size() < kMinHourRows || on_hours.size() == rows.size()) {
    return rule;
  }
  std::vector<double> all_on_flow;
  for (const auto& v : flow_by_hour) all_on_flow.insert(all_on_flow.end(), v.begin(), v.end());
  const double overall = SampleQuantile(&all_on_flow, 0.5);
  for (auto& v : flow_by_hour) {
    rule.flow_by_hour_kg_s.push_back(v.size() >= kMinHourRows ? SampleQuantile(&v, 0.5) : overall);
  }
  rule.first_hour = SampleQuantile(&on_hours, 0.01);
  rule.last_hour = SampleQuantile(&on_hours, 0.99);
  // Outside the rule's hours it is off: those rows are right when off.
  std::size_t outside_right = 0;
  std::vector<Row> inside;
  for (const Row& r : rows) {
    if (r.hour >= rule.first_hour && r.hour <= rule.last_hour) {
      inside.push_back(r);
    } else {
      outside_right += r.on ? 0 : 1;
    }
  }
  std::size_t best = 0;
  for (double on = 0.0; on <= kGridMaxWM2; on += kGridStepWM2) {
    for (double off = 0.0; off <= on; off += kGridStepWM2) {
      const std::size_t right = Matches(inside, on, off, max_gap_s);
      if (right > best) {
        best = right;
        rule.g_on_w_m2 = on;
        rule.g_off_w_m2 = off;
      }
    }
  }
  best += outside_right;
  rule.accuracy = static_cast<double>(best) / static_cast<double>(rows.size());
  rule.valid = true;
  return rule;
}

std::vector<double> PumpFlow(const Plant& plant, const PumpRule& rule, const Series& inputs,
                             bool on_at_start) {
  const Channel g_channel = rule.on_plane ? Channel::kGPoaWM2 : Channel::kGhiWM2;
  std::vector<double> flow(inputs.size(), std::numeric_limits<double>::quiet_NaN());
  if (!rule.valid || !inputs.Has(g_channel)) return flow;
  bool state = on_at_start;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const double g = inputs[g_channel][k];
    const double hour = SolarHour(plant, inputs.time_s[k]);
    const bool window = hour >= rule.first_hour && hour <= rule.last_hour;
    if (std::isfinite(g)) state = window && (state ? g >= rule.g_off_w_m2 : g >= rule.g_on_w_m2);
    flow[k] = state ? rule.flow_by_hour_kg_s[static_cast<std::size_t>(hour) % 24] : 0.0;
  }
  return flow;
}

}  // namespace pvtwin
