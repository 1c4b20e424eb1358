#include "core/forecast/forecast.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "core/data/resample.h"
#include "core/forecast/operation_forecast.h"
#include "core/forecast/weather_resample.h"
#include "core/model/thermal_model.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// During the warm-up a missing minute (e.g. the one not yet aggregated when
// the forecast is issued) holds the last measured value this long; a
// history at a coarser step (10-, 15-min interval rows) holds it one row,
// the interval not yet logged when the forecast is issued.
constexpr double kWarmupHoldS = 600.0;

// Weather channels a forecast carries into the horizon (the model's inputs
// other than the operation). The measured angle of incidence is left out:
// the model computes it from the sun position for every row alike.
constexpr Channel kWeatherChannels[] = {
    Channel::kGPoaWM2,        Channel::kGhiWM2,    Channel::kDhiWM2,
    Channel::kGPoaDiffuseWM2, Channel::kTAmbC,     Channel::kWindMS,
    Channel::kTSkyC,          Channel::kLwDownWM2, Channel::kTBackC};
constexpr Channel kOperationChannels[] = {Channel::kTInC, Channel::kMdotKgS};

// The finite values of one channel, sorted by time, for lookups.
struct Track {
  std::vector<std::int64_t> time_s;
  std::vector<double> value;

  Track(const Series& s, Channel c) {
    if (!s.Has(c)) return;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (std::isfinite(s[c][i])) {
        time_s.push_back(s.time_s[i]);
        value.push_back(s[c][i]);
      }
    }
  }

  double Exact(std::int64_t t) const {
    auto it = std::lower_bound(time_s.begin(), time_s.end(), t);
    return it != time_s.end() && *it == t ? value[static_cast<std::size_t>(it - time_s.begin())]
                                          : kNaN;
  }

  // Linear between the neighbours when they are at most max_gap_s apart.
  double Interpolated(std::int64_t t, double max_gap_s) const {
    auto it = std::lower_bound(time_s.begin(), time_s.end(), t);
    if (it == time_s.end()) return kNaN;
    const std::size_t j = static_cast<std::size_t>(it - time_s.begin());
    if (*it == t) return value[j];
    if (j == 0 || static_cast<double>(time_s[j] - time_s[j - 1]) > max_gap_s) return kNaN;
    const double w =
        static_cast<double>(t - time_s[j - 1]) / static_cast<double>(time_s[j] - time_s[j - 1]);
    return value[j - 1] + w * (value[j] - value[j - 1]);
  }

  // The latest value at or before t, if at most max_gap_s old (a plan holds
  // its set point until the next entry).
  double Held(std::int64_t t, double max_gap_s) const {
    auto it = std::upper_bound(time_s.begin(), time_s.end(), t);
    if (it == time_s.begin()) return kNaN;
    const std::size_t j = static_cast<std::size_t>(it - time_s.begin()) - 1;
    return static_cast<double>(t - time_s[j]) <= max_gap_s ? value[j] : kNaN;
  }
};

// Median, over the history's days, of the value at each step of the UTC day.
std::vector<double> TypicalDay(const Track& track, double step_s) {
  const std::size_t slots = static_cast<std::size_t>(std::lround(86400.0 / step_s));
  std::vector<std::vector<double>> by_slot(slots);
  for (std::size_t i = 0; i < track.time_s.size(); ++i) {
    const std::int64_t second_of_day = ((track.time_s[i] % 86400) + 86400) % 86400;
    const auto slot = static_cast<std::size_t>(static_cast<double>(second_of_day) / step_s);
    if (slot < slots) by_slot[slot].push_back(track.value[i]);
  }
  std::vector<double> median(slots, kNaN);
  for (std::size_t k = 0; k < slots; ++k) {
    std::vector<double>& v = by_slot[k];
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    median[k] = v[v.size() / 2];
  }
  return median;
}

// Column c of `in`: the warm-up rows (the first n_warm) from the measured
// track, holding the last value across short gaps; horizon row h (at time t)
// from horizon_value(h, t).
template <class HorizonValue>
void FillColumn(const Track& measured, std::size_t n_warm, Series* in, Channel c,
                HorizonValue horizon_value) {
  std::vector<double>& col = in->Ensure(c);
  const double hold_s = std::max(kWarmupHoldS, in->step_s);
  for (std::size_t k = 0; k < col.size(); ++k) {
    const std::int64_t t = in->time_s[k];
    col[k] = k < n_warm ? measured.Held(t, hold_s) : horizon_value(k - n_warm, t);
  }
}

}  // namespace

std::string ForecastInputUse::Describe() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "weather: forecast %zu/%zu, persistence %zu/%zu, missing %zu/%zu; "
                "operation: plan %zu/%zu, typical day %zu/%zu, learned %zu/%zu",
                weather_forecast, rows, weather_persistence, rows, weather_missing, rows,
                operation_plan, rows, operation_typical, rows, operation_learned, rows);
  std::string text = buf;
  std::string list;
  bool table_used = false;
  for (const ChannelInputUse& c : channels) {
    const char* primary = c.operation ? "operation_plan" : "weather_forecast";
    const char* fallback =
        c.operation ? (c.learned ? "learned_rule" : "typical_day") : "persistence";
    std::string parts;
    const auto add = [&parts](const char* name, std::size_t n) {
      if (n > 0) parts += (parts.empty() ? "" : "+") + std::string(name) + " " + std::to_string(n);
    };
    add(primary, c.forecast);
    add(fallback, c.fallback);
    add("missing", c.missing);
    if (parts.empty()) continue;
    table_used = table_used || (!c.operation && c.forecast > 0);
    list += (list.empty() ? "" : ", ") + std::string(ChannelName(c.channel)) + "=" + parts;
  }
  if (!list.empty()) text += "; channels: " + list;
  if (!pump_rule.empty()) text += "; " + pump_rule;
  if (table_used && !weather_sources.empty()) {
    text += "; weather_forecast source: ";
    bool above_clear_sky = false;
    for (std::size_t i = 0; i < weather_sources.size(); ++i) {
      text += (i ? " | " : "") + weather_sources[i];
      above_clear_sky =
          above_clear_sky || weather_sources[i].find(kAboveClearSkyMark) != std::string::npos;
    }
    if (above_clear_sky) text += "; " + std::string(kAboveClearSkyInputs);
  }
  return text;
}

namespace {

const Series kNoRows;

bool IsIrradiance(Channel c) {
  return c == Channel::kGPoaWM2 || c == Channel::kGhiWM2 || c == Channel::kDhiWM2 ||
         c == Channel::kGPoaDiffuseWM2;
}

// The rows of a forecast run: the warm-up, then the horizon.
Series MakeFrame(const ForecastRequest& request, std::size_t n_warm, std::size_t n) {
  const std::int64_t step = std::llround(request.step_s);
  Series in;
  in.step_s = request.step_s;
  in.time_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    in.time_s[k] = request.issued_at_s - static_cast<std::int64_t>(n_warm) * step +
                   static_cast<std::int64_t>(k) * step;
  }
  in[Channel::kValid].assign(n, 1.0);
  return in;
}

// The measured value 24 h before t, else 48 h, … back over the history's span.
double Persisted(const Track& measured, std::int64_t t, std::int64_t history_span_s,
                 std::int64_t* back_s) {
  double v = kNaN;
  std::int64_t back = 86400;
  for (; back <= history_span_s + 86400 && std::isnan(v); back += 86400) {
    v = measured.Exact(t - back);
  }
  if (back_s != nullptr) *back_s = back - 86400;
  return v;
}

// The weather channels: warm-up measured; horizon from the weather forecast
// table where it has the channel (when use_table), else persisted. Counts the
// sources into *use and flags the rows whose irradiance all came from the
// table (and no weather channel is missing), and those with a persisted
// irradiance channel (*irradiance_persisted).
void FillWeather(const Series& history, const Series& weather_forecast,
                 const ForecastRequest& request, std::size_t n_warm, bool use_table, Series* in,
                 ForecastInputUse* use, std::vector<std::uint8_t>* from_table,
                 std::vector<std::uint8_t>* irradiance_persisted) {
  const std::size_t n_horizon = in->size() - n_warm;
  const std::int64_t history_span_s = history.time_s.back() - history.time_s.front();
  from_table->assign(n_horizon, use_table ? 1 : 0);
  irradiance_persisted->assign(n_horizon, 0);
  std::vector<std::uint8_t> persisted(n_horizon, 0), missing(n_horizon, 0);
  // A forecast's irradiance is one set: where the table has irradiance, an
  // irradiance channel it lacks (the in-plane diffuse of a GTI-only
  // provider) is left out of the run rather than persisted beside it; the
  // model then splits the forecast's own irradiance (paper eq. 2.5).
  bool table_has_irradiance = false;
  for (Channel c : kWeatherChannels) {
    table_has_irradiance = table_has_irradiance || (use_table && IsIrradiance(c) &&
                                                    !Track(weather_forecast, c).time_s.empty());
  }
  for (Channel c : kWeatherChannels) {
    if (!history.Has(c)) continue;
    const Track measured(history, c);
    if (measured.time_s.empty()) continue;
    const Track predicted(use_table ? weather_forecast : kNoRows, c);
    if (table_has_irradiance && IsIrradiance(c) && predicted.time_s.empty()) continue;
    ChannelInputUse channel_use{c};
    FillColumn(measured, n_warm, in, c, [&](std::size_t h, std::int64_t t) {
      double v = predicted.Interpolated(t, request.max_interp_gap_s);
      if (!std::isnan(v)) {
        ++channel_use.forecast;
        return v;
      }
      if (IsIrradiance(c)) (*from_table)[h] = 0;
      v = Persisted(measured, t, history_span_s, nullptr);
      (std::isnan(v) ? missing : persisted)[h] = 1;
      if (IsIrradiance(c) && !std::isnan(v)) (*irradiance_persisted)[h] = 1;
      ++(std::isnan(v) ? channel_use.missing : channel_use.fallback);
      return v;
    });
    use->channels.push_back(channel_use);
  }
  for (std::size_t h = 0; h < n_horizon; ++h) {
    (*from_table)[h] = (*from_table)[h] && !missing[h];
    use->weather_forecast += (*from_table)[h];
    use->weather_persistence += persisted[h];
    use->weather_missing += missing[h];
  }
}

// The inlet's typical day shifted to the level of the history's last 24 h
// (operation_forecast.h), per slot of the day.
std::vector<double> ShiftedToLastDay(const Track& measured, std::vector<double> typical,
                                     double step_s) {
  if (measured.time_s.empty()) return typical;
  const std::int64_t last = measured.time_s.back();
  double sum_measured = 0.0, sum_typical = 0.0;
  std::size_t n = 0;
  for (std::size_t i = measured.time_s.size(); i-- > 0 && measured.time_s[i] > last - 86400;) {
    const std::int64_t second_of_day = ((measured.time_s[i] % 86400) + 86400) % 86400;
    const auto slot = static_cast<std::size_t>(static_cast<double>(second_of_day) / step_s);
    if (slot >= typical.size() || std::isnan(typical[slot])) continue;
    sum_measured += measured.value[i];
    sum_typical += typical[slot];
    ++n;
  }
  if (n == 0) return typical;
  const double offset = (sum_measured - sum_typical) / static_cast<double>(n);
  for (double& v : typical) v += offset;
  return typical;
}

// The operation channels without a plan, per row of `in`: the typical day,
// or the learned rule (operation_forecast.h) on the rows' irradiance.
std::vector<double> OperationFallback(const Plant& plant, const Series& history,
                                      const ForecastRequest& request, Channel c, const Series& in,
                                      const PumpRule* rule) {
  const Track measured(history, c);
  std::vector<double> typical = TypicalDay(
      request.operation_history ? Track(*request.operation_history, c) : measured, request.step_s);
  if (rule != nullptr && c == Channel::kMdotKgS) return PumpFlow(plant, *rule, in, false);
  if (rule != nullptr) typical = ShiftedToLastDay(measured, std::move(typical), request.step_s);
  const std::int64_t step = std::llround(request.step_s);
  std::vector<double> v(in.size(), kNaN);
  for (std::size_t k = 0; k < in.size(); ++k) {
    const std::int64_t second_of_day = ((in.time_s[k] % 86400) + 86400) % 86400;
    const auto slot = static_cast<std::size_t>(second_of_day / step);
    if (slot < typical.size()) v[k] = typical[slot];
  }
  return v;
}

// The operation channels: warm-up measured; horizon from the plan (when
// use_plan), else the window's typical day or the learned rule.
void FillOperation(const Plant& plant, const Series& history, const Series& operation_plan,
                   const ForecastRequest& request, std::size_t n_warm, bool use_plan,
                   const PumpRule* rule, Series* in, ForecastInputUse* use) {
  const std::size_t n_horizon = in->size() - n_warm;
  std::vector<std::uint8_t> planned(n_horizon, 1), fallback_used(n_horizon, 0);
  for (Channel c : kOperationChannels) {
    const Track measured(history, c);
    const Track planned_track(use_plan ? operation_plan : kNoRows, c);
    const std::vector<double> fallback = OperationFallback(plant, history, request, c, *in, rule);
    ChannelInputUse channel_use{c};
    channel_use.operation = true;
    channel_use.learned = rule != nullptr;
    FillColumn(measured, n_warm, in, c, [&](std::size_t h, std::int64_t t) {
      double v = planned_track.Held(t, request.max_interp_gap_s);
      if (!std::isnan(v)) {
        ++channel_use.forecast;
        return v;
      }
      planned[h] = 0;
      v = fallback[n_warm + h];
      if (!std::isnan(v)) fallback_used[h] = 1;
      ++(std::isnan(v) ? channel_use.missing : channel_use.fallback);
      return v;
    });
    use->channels.push_back(channel_use);
  }
  for (std::size_t h = 0; h < n_horizon; ++h) {
    use->operation_plan += planned[h];
    (rule != nullptr ? use->operation_learned : use->operation_typical) += fallback_used[h];
  }
}

// Smart persistence of the irradiance channels on the horizon rows h with
// rows[h] set (see the header): the horizon value at t is k·clear(t), k the clear-sky index
// of the measured hour around t − back (the persistence day) against the
// clear sky of the channel's kind (in-plane or horizontal), 0 ≤ k ≤
// kMaxClearSkyIndex. Near the horizon (clear-sky mean of that hour below
// kMinClearSkyWM2) and beyond two days back the plain persisted value stays.
constexpr double kMaxClearSkyIndex = 1.5;
constexpr double kMinClearSkyWM2 = 5.0;
constexpr double kLinkeTurbidity = 3.0;

void SmartPersistIrradiance(const Plant& plant, const Series& history, std::size_t n_warm,
                            const std::vector<std::uint8_t>& rows, Series* in) {
  constexpr Channel kIrradiance[] = {Channel::kGPoaWM2, Channel::kGhiWM2, Channel::kDhiWM2,
                                     Channel::kGPoaDiffuseWM2};
  if (in->size() <= n_warm) return;
  const std::int64_t h0 = in->time_s[n_warm];
  const std::int64_t grid_begin = h0 - 2 * 86400 - 3600;
  const ClearSkyGrid grid =
      MakeClearSkyGrid(plant, grid_begin, in->time_s.back() + 3600, kLinkeTurbidity);
  const std::int64_t history_span_s = history.time_s.back() - history.time_s.front();
  for (Channel c : kIrradiance) {
    if (!in->Has(c) || !history.Has(c)) continue;
    const bool on_plane = c == Channel::kGPoaWM2 || c == Channel::kGPoaDiffuseWM2;
    const std::vector<double>& clear = on_plane ? grid.clear_poa_w_m2 : grid.clear_ghi_w_m2;
    const auto clear_at = [&](std::int64_t t) {
      const std::int64_t k = (t - grid_begin) / 60;
      return k >= 0 && static_cast<std::size_t>(k) < clear.size()
                 ? clear[static_cast<std::size_t>(k)]
                 : kNaN;
    };
    const Track measured(history, c);
    std::vector<double>& col = (*in)[c];
    for (std::size_t k = n_warm; k < in->size(); ++k) {
      if (!rows[k - n_warm]) continue;
      const std::int64_t t = in->time_s[k];
      std::int64_t back = 0;
      if (std::isnan(Persisted(measured, t, history_span_s, &back)) || back > 2 * 86400) continue;
      double sum = 0.0, sum_clear = 0.0;
      std::size_t minutes = 0;
      auto it = std::lower_bound(measured.time_s.begin(), measured.time_s.end(), t - back - 1800);
      for (; it != measured.time_s.end() && *it < t - back + 1800; ++it) {
        const double cs = clear_at(*it);
        if (std::isnan(cs)) continue;
        sum += measured.value[static_cast<std::size_t>(it - measured.time_s.begin())];
        sum_clear += cs;
        ++minutes;
      }
      if (minutes == 0 || sum_clear < kMinClearSkyWM2 * static_cast<double>(minutes)) continue;
      const double index = std::clamp(sum / sum_clear, 0.0, kMaxClearSkyIndex);
      col[k] = index * clear_at(t);
    }
  }
}

// The weather forecast table as the forecast's rows need it: when the
// forecast runs at a coarser step than the table's rows (interval history of
// a 10- or 15-min logger against the table's 1-min rows), each row's mean
// over [t, t + step_s), the grid at issued_at's phase; the model's inputs
// are interval means, as the measured rows it was calibrated on, not the
// table's value at the interval's start. Else the table itself.
const Series& WeatherAtStep(const Series& table, const ForecastRequest& request, Series* averaged) {
  if (table.size() == 0 || !(table.step_s > 0.0) || request.step_s <= table.step_s) return table;
  const std::int64_t step = std::llround(request.step_s);
  const std::int64_t phase = ((request.issued_at_s % step) + step) % step;
  Series shifted = table;
  for (std::int64_t& t : shifted.time_s) t -= phase;
  std::string not_a_multiple;
  if (!Resample(shifted, request.step_s, averaged, &not_a_multiple)) return table;
  for (std::int64_t& t : averaged->time_s) t += phase;
  return *averaged;
}

// Runs the model over `in` and keeps the horizon rows of its outputs.
bool RunHorizon(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                const Series& in, std::size_t n_warm, bool all_outputs, Series* rows,
                std::string* error) {
  Drivers drivers;
  if (!PrepareDrivers(in, plant, spec, &drivers, error)) return false;
  SimOutputs sim;
  Simulate(drivers, params, &sim);
  *rows = Series{};
  rows->step_s = in.step_s;
  rows->time_s.assign(in.time_s.begin() + static_cast<std::ptrdiff_t>(n_warm), in.time_s.end());
  auto take = [&](Channel c, const std::vector<double>& v) {
    (*rows)[c].assign(v.begin() + static_cast<std::ptrdiff_t>(n_warm), v.end());
  };
  take(Channel::kPElW, sim.p_el_w);
  take(Channel::kQThW, sim.q_th_w);
  if (!all_outputs) return true;
  take(Channel::kTPvC, sim.t_pv_c);
  take(Channel::kTOutC, sim.t_out_c);
  return true;
}

}  // namespace

bool MakeForecast(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                  const Series& history, const Series& weather_forecast,
                  const Series& operation_plan, const ForecastRequest& request, Forecast* out,
                  std::string* error) {
  if (request.step_s <= 0 || request.horizon_s < request.step_s || request.warmup_s < 0) {
    *error = "forecast request: step, horizon or warm-up out of range";
    return false;
  }
  if (history.size() == 0) {
    *error = "no measured history before the forecast";
    return false;
  }
  const std::int64_t step = std::llround(request.step_s);
  const std::size_t n_warm = static_cast<std::size_t>(request.warmup_s / request.step_s);
  const std::size_t n = n_warm + static_cast<std::size_t>(request.horizon_s / request.step_s);
  // Persistence reaches back at most over the history's span.
  if (history.time_s.back() - history.time_s.front() < 86400 - step) {
    *error = "the measured history spans less than one day; persistence needs a full day";
    return false;
  }

  Series in = MakeFrame(request, n_warm, n);
  ForecastInputUse use;
  use.rows = n - n_warm;
  Series averaged;
  std::vector<std::uint8_t> persisted;
  FillWeather(history, WeatherAtStep(weather_forecast, request, &averaged), request, n_warm, true,
              &in, &use, &out->weather_from_forecast, &persisted);
  SmartPersistIrradiance(plant, history, n_warm, persisted, &in);
  PumpRule rule;
  if (request.operation == OperationForecast::kLearned) {
    rule = LearnPumpRule(plant, request.operation_history ? *request.operation_history : history);
    use.pump_rule = rule.Describe();
  }
  FillOperation(plant, history, operation_plan, request, n_warm, true, rule.valid ? &rule : nullptr,
                &in, &use);
  if (!RunHorizon(plant, spec, params, in, n_warm, true, &out->rows, error)) return false;
  out->inputs = use;
  out->inputs_used = in.Slice(n_warm, n);
  if (!request.with_reference) return true;

  Series ref = MakeFrame(request, n_warm, n);
  ForecastInputUse ref_use;
  std::vector<std::uint8_t> ref_from_table;
  std::vector<std::uint8_t> ref_persisted;
  FillWeather(history, Series{}, request, n_warm, false, &ref, &ref_use, &ref_from_table,
              &ref_persisted);
  SmartPersistIrradiance(plant, history, n_warm, ref_persisted, &ref);
  FillOperation(plant, history, Series{}, request, n_warm, false, nullptr, &ref, &ref_use);
  return RunHorizon(plant, spec, params, ref, n_warm, false, &out->reference, error);
}

}  // namespace pvtwin
