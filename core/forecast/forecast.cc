#include "core/forecast/forecast.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "core/model/thermal_model.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// During the warm-up a missing minute (e.g. the one not yet aggregated when
// the forecast is issued) holds the last measured value this long.
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
  for (std::size_t k = 0; k < col.size(); ++k) {
    const std::int64_t t = in->time_s[k];
    col[k] = k < n_warm ? measured.Held(t, kWarmupHoldS) : horizon_value(k - n_warm, t);
  }
}

}  // namespace

std::string ForecastInputUse::Describe() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "weather: forecast %zu/%zu, persistence %zu/%zu, missing %zu/%zu; "
                "operation: plan %zu/%zu, typical day %zu/%zu",
                weather_forecast, rows, weather_persistence, rows, weather_missing, rows,
                operation_plan, rows, operation_typical, rows);
  std::string text = buf;
  std::string list;
  bool table_used = false;
  for (const ChannelInputUse& c : channels) {
    const char* primary = c.operation ? "operation_plan" : "weather_forecast";
    const char* fallback = c.operation ? "typical_day" : "persistence";
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
  if (table_used && !weather_sources.empty()) {
    text += "; weather_forecast source: ";
    for (std::size_t i = 0; i < weather_sources.size(); ++i) {
      text += (i ? " | " : "") + weather_sources[i];
    }
  }
  return text;
}

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
  const std::int64_t t0 = request.issued_at_s;
  const std::size_t n_warm = static_cast<std::size_t>(request.warmup_s / request.step_s);
  const std::size_t n_horizon = static_cast<std::size_t>(request.horizon_s / request.step_s);
  const std::size_t n = n_warm + n_horizon;
  // Persistence reaches back at most over the history's span.
  const std::int64_t history_span_s = history.time_s.back() - history.time_s.front();
  if (history_span_s < 86400 - step) {
    *error = "the measured history spans less than one day; persistence needs a full day";
    return false;
  }

  Series in;
  in.step_s = request.step_s;
  in.time_s.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    in.time_s[k] =
        t0 - static_cast<std::int64_t>(n_warm) * step + static_cast<std::int64_t>(k) * step;
  }
  in[Channel::kValid].assign(n, 1.0);

  ForecastInputUse use;
  use.rows = n_horizon;
  std::vector<std::uint8_t> row_from_forecast(n_horizon, 1), row_persisted(n_horizon, 0),
      row_missing(n_horizon, 0);
  for (Channel c : kWeatherChannels) {
    if (!history.Has(c)) continue;
    const Track measured(history, c);
    if (measured.time_s.empty()) continue;
    const Track predicted(weather_forecast, c);
    ChannelInputUse channel_use{c};
    FillColumn(measured, n_warm, &in, c, [&](std::size_t h, std::int64_t t) {
      double v = predicted.Interpolated(t, request.max_interp_gap_s);
      if (!std::isnan(v)) {
        ++channel_use.forecast;
      } else {
        row_from_forecast[h] = 0;
        for (std::int64_t back = 86400; back <= history_span_s + 86400 && std::isnan(v);
             back += 86400) {
          v = measured.Exact(t - back);
        }
        (std::isnan(v) ? row_missing : row_persisted)[h] = 1;
        ++(std::isnan(v) ? channel_use.missing : channel_use.fallback);
      }
      return v;
    });
    use.channels.push_back(channel_use);
  }
  for (std::size_t h = 0; h < n_horizon; ++h) {
    use.weather_forecast += row_from_forecast[h] && !row_missing[h];
    use.weather_persistence += row_persisted[h];
    use.weather_missing += row_missing[h];
  }

  std::vector<std::uint8_t> row_planned(n_horizon, 1), row_typical(n_horizon, 0);
  for (Channel c : kOperationChannels) {
    const Track measured(history, c);
    const Track planned(operation_plan, c);
    const std::vector<double> typical = TypicalDay(measured, request.step_s);
    ChannelInputUse channel_use{c};
    channel_use.operation = true;
    FillColumn(measured, n_warm, &in, c, [&](std::size_t h, std::int64_t t) {
      double v = planned.Held(t, request.max_interp_gap_s);
      if (!std::isnan(v)) {
        ++channel_use.forecast;
      } else {
        row_planned[h] = 0;
        const std::int64_t second_of_day = ((t % 86400) + 86400) % 86400;
        const auto slot = static_cast<std::size_t>(second_of_day / step);
        v = slot < typical.size() ? typical[slot] : kNaN;
        if (!std::isnan(v)) row_typical[h] = 1;
        ++(std::isnan(v) ? channel_use.missing : channel_use.fallback);
      }
      return v;
    });
    use.channels.push_back(channel_use);
  }
  for (std::size_t h = 0; h < n_horizon; ++h) {
    use.operation_plan += row_planned[h];
    use.operation_typical += row_typical[h];
  }

  Drivers drivers;
  if (!PrepareDrivers(in, plant, spec, &drivers, error)) return false;
  SimOutputs sim;
  Simulate(drivers, params, &sim);

  Series& rows = out->rows;
  rows = Series{};
  rows.step_s = request.step_s;
  rows.time_s.assign(in.time_s.begin() + static_cast<std::ptrdiff_t>(n_warm), in.time_s.end());
  auto take = [&](Channel c, const std::vector<double>& v) {
    rows[c].assign(v.begin() + static_cast<std::ptrdiff_t>(n_warm), v.end());
  };
  take(Channel::kPElW, sim.p_el_w);
  take(Channel::kQThW, sim.q_th_w);
  take(Channel::kTPvC, sim.t_pv_c);
  take(Channel::kTOutC, sim.t_out_c);
  out->inputs = use;
  out->inputs_used = in.Slice(n_warm, n);
  return true;
}

}  // namespace pvtwin
