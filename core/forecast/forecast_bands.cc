#include "core/forecast/forecast_bands.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>

#include "core/common/units.h"
#include "core/forecast/operation_forecast.h"
#include "core/forecast/weather_resample.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr std::int64_t kDayS = 86400;
constexpr double kIrradianceEdgesWM2[] = {20.0, 200.0, 600.0};
constexpr double kClearIndex = 0.6;
constexpr double kLinkeTurbidity = 3.0;

std::int64_t DayStart(std::int64_t t) { return t - ((t % kDayS) + kDayS) % kDayS; }

// Regime levels, finest first: which features a level's key keeps.
constexpr int kLevels = 5;
std::uint32_t KeyAt(const ForecastRegime& r, int level) {
  const bool sky = level <= 1, time = level == 0, pump = level <= 2, irradiance = level <= 3,
             lead = level <= 1;
  std::uint32_t key = static_cast<std::uint32_t>(level) << 20;
  if (irradiance) key |= static_cast<std::uint32_t>(r.irradiance + 1);
  if (sky) key |= static_cast<std::uint32_t>(r.sky + 1) << 4;
  if (time) key |= static_cast<std::uint32_t>(r.time + 1) << 8;
  if (pump) key |= static_cast<std::uint32_t>(r.pump + 1) << 12;
  if (lead) key |= static_cast<std::uint32_t>(r.lead + 1) << 16;
  return key;
}

struct Quantiles {
  double p_lo = kNaN, p_mid = kNaN, p_hi = kNaN, q_lo = kNaN, q_mid = kNaN, q_hi = kNaN;
};

// Per regime key (all levels) of one source: the quantiles of the keys
// holding at least min_samples errors of an output.
// skip_issue: leave out the errors of the forecast issued then.
std::map<std::uint32_t, Quantiles> QuantileTable(
    const std::vector<ForecastError>& errors, const BandOptions& options,
    std::int64_t skip_issue = std::numeric_limits<std::int64_t>::min()) {
  struct Samples {
    std::vector<double> p, q;
    std::set<std::int64_t> p_days, q_days;
  };
  std::map<std::uint32_t, Samples> samples;
  for (const ForecastError& e : errors) {
    if (e.issued_at_s == skip_issue) continue;
    const std::int64_t day = e.issued_at_s;
    for (int level = 0; level < kLevels; ++level) {
      Samples& s = samples[KeyAt(e.regime, level)];
      if (std::isfinite(e.p_el_w)) {
        s.p.push_back(e.p_el_w);
        s.p_days.insert(day);
      }
      if (std::isfinite(e.q_th_w)) {
        s.q.push_back(e.q_th_w);
        s.q_days.insert(day);
      }
    }
  }
  std::map<std::uint32_t, Quantiles> table;
  for (auto& [key, s] : samples) {
    const bool all_rows = (key >> 16) == kLevels - 1;
    const auto enough = [&](const std::vector<double>& v, const std::set<std::int64_t>& d) {
      return v.size() >= options.min_samples && (all_rows || d.size() >= options.min_days);
    };
    Quantiles& out = table[key];
    // The levels themselves: the calibration on held-out days (BandsFor)
    // corrects the width for what a new day does.
    if (enough(s.p, s.p_days)) {
      out.p_lo = SampleQuantile(&s.p, options.lower_quantile);
      out.p_mid = SampleQuantile(&s.p, 0.5);
      out.p_hi = SampleQuantile(&s.p, options.upper_quantile);
    }
    if (enough(s.q, s.q_days)) {
      out.q_lo = SampleQuantile(&s.q, options.lower_quantile);
      out.q_mid = SampleQuantile(&s.q, 0.5);
      out.q_hi = SampleQuantile(&s.q, options.upper_quantile);
    }
  }
  return table;
}

// The finest level's quantiles of one output for a regime.
struct Offsets {
  double lo = kNaN, mid = kNaN, hi = kNaN;
};
Offsets Lookup(const std::map<std::uint32_t, Quantiles>& table, const ForecastRegime& r,
               bool p_el) {
  for (int level = 0; level < kLevels; ++level) {
    const auto it = table.find(KeyAt(r, level));
    if (it == table.end()) continue;
    const Quantiles& q = it->second;
    const Offsets o = p_el ? Offsets{q.p_lo, q.p_mid, q.p_hi} : Offsets{q.q_lo, q.q_mid, q.q_hi};
    if (!std::isnan(o.lo)) return o;
  }
  return {};
}

// Errors of one replayed forecast against the measured rows, into *out.
void Score(const Forecast& f, const std::vector<ForecastRegime>& regimes, const Series& history,
           bool only_table_rows, std::vector<ForecastError>* out) {
  const std::vector<double>& p = history[Channel::kPElW];
  const std::vector<double>& q = history[Channel::kQThW];
  const bool has_valid = history.Has(Channel::kValid);
  for (std::size_t h = 0; h < f.rows.size(); ++h) {
    if (only_table_rows && !f.weather_from_forecast[h]) continue;
    const std::int64_t t = f.rows.time_s[h];
    const auto it = std::lower_bound(history.time_s.begin(), history.time_s.end(), t);
    if (it == history.time_s.end() || *it != t) continue;
    const auto i = static_cast<std::size_t>(it - history.time_s.begin());
    if (has_valid && history[Channel::kValid][i] == 0.0) continue;
    ForecastError e{regimes[h], t, f.rows.time_s.front(), p[i] - f.rows[Channel::kPElW][h],
                    q[i] - f.rows[Channel::kQThW][h]};
    if (std::isfinite(e.p_el_w) || std::isfinite(e.q_th_w)) out->push_back(e);
  }
}

}  // namespace

const char* WeatherSourceName(WeatherSource source) {
  return source == WeatherSource::kWeatherForecast ? "weather_forecast" : "persistence";
}

double SampleQuantile(std::vector<double>* values, double q) {
  if (values->empty()) return kNaN;
  std::sort(values->begin(), values->end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values->size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, values->size() - 1);
  return (*values)[lo] + (pos - static_cast<double>(lo)) * ((*values)[hi] - (*values)[lo]);
}

std::vector<ForecastRegime> RegimesOf(const Plant& plant, const Series& inputs) {
  std::vector<ForecastRegime> regimes(inputs.size());
  if (inputs.size() == 0) return regimes;
  const bool on_plane = inputs.Has(Channel::kGPoaWM2);
  const Channel g_channel = on_plane ? Channel::kGPoaWM2 : Channel::kGhiWM2;
  const ClearSkyGrid grid =
      MakeClearSkyGrid(plant, inputs.time_s.front(), inputs.time_s.back() + 60, kLinkeTurbidity);
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    ForecastRegime& r = regimes[k];
    const double g = inputs.Has(g_channel) ? inputs[g_channel][k] : kNaN;
    const double g0 = std::isnan(g) ? 0.0 : g;
    r.irradiance = static_cast<std::uint8_t>(
        std::upper_bound(std::begin(kIrradianceEdgesWM2), std::end(kIrradianceEdgesWM2), g0) -
        std::begin(kIrradianceEdgesWM2));
    const auto m = static_cast<std::size_t>((inputs.time_s[k] - grid.time_s.front()) / 60);
    const double clear =
        m < grid.time_s.size() ? (on_plane ? grid.clear_poa_w_m2 : grid.clear_ghi_w_m2)[m] : 0.0;
    r.sky = clear > 0.0 && g0 >= kClearIndex * clear ? 0 : 1;
    const double solar_h = SolarHour(plant, inputs.time_s[k] + 30);
    r.time = solar_h < 10.0 ? 0 : (solar_h < 14.0 ? 1 : 2);
    const double flow = inputs.Has(Channel::kMdotKgS) ? inputs[Channel::kMdotKgS][k] : kNaN;
    r.pump = std::isfinite(flow) && flow > 0.0 ? 1 : 0;
    const std::int64_t lead_s = inputs.time_s[k] - inputs.time_s.front();
    r.lead = lead_s < 3600 ? 0 : (lead_s < 6 * 3600 ? 1 : 2);
  }
  return regimes;
}

namespace {

// The rows of s outside [from, to).
Series WithoutRows(const Series& s, std::int64_t from, std::int64_t to) {
  const std::size_t a = s.RowAtOrAfter(from), b = std::max(a, s.RowAtOrAfter(to));
  Series out = s.Slice(0, a);
  const Series tail = s.Slice(b, s.size());
  out.time_s.insert(out.time_s.end(), tail.time_s.begin(), tail.time_s.end());
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    const auto channel = static_cast<Channel>(c);
    if (!s.Has(channel)) continue;
    std::vector<double>& col = out.Ensure(channel);
    col.resize(a, kNaN);
    const std::vector<double>& t = tail[channel];
    col.insert(col.end(), t.begin(), t.end());
    col.resize(out.time_s.size(), kNaN);
  }
  return out;
}

// Calls per_day(request of the replayed day, history before it; its
// operation learned from the history's other days) for each UTC day D of the
// history with a full day of history before D + the request's time of day
// (the replayed issue), until it returns false.
template <class PerDay>
void ForEachReplayDay(const Series& history, const ForecastRequest& request, PerDay per_day) {
  if (history.size() == 0) return;
  ForecastRequest day = request;
  day.horizon_s = static_cast<double>(kDayS);
  day.with_reference = false;
  const std::int64_t time_of_day = request.issued_at_s - DayStart(request.issued_at_s);
  const std::int64_t first_day = DayStart(history.time_s.front()) + kDayS;
  for (std::int64_t d = first_day + time_of_day; d <= history.time_s.back(); d += kDayS) {
    const auto end = static_cast<std::size_t>(
        std::lower_bound(history.time_s.begin(), history.time_s.end(), d) - history.time_s.begin());
    const Series before = history.Slice(0, end);
    if (before.size() == 0 ||
        before.time_s.back() - before.time_s.front() < kDayS - std::llround(request.step_s)) {
      continue;
    }
    day.issued_at_s = d;
    const Series others = WithoutRows(history, d, d + kDayS);
    day.operation_history = &others;
    if (!per_day(day, before)) return;
  }
}

}  // namespace

namespace {

// The replayed errors of one weather source (the history's days on which
// that source has rows) into out->by_source[source] and out->days[source].
bool ReplaySource(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                  const Series& history, const Series& past_weather_forecast,
                  const ForecastRequest& request, WeatherSource source, ForecastErrors* out,
                  std::string* error) {
  const auto s = static_cast<std::size_t>(source);
  const bool table = source == WeatherSource::kWeatherForecast;
  bool ok = true;
  ForEachReplayDay(history, request, [&](const ForecastRequest& day, const Series& before) {
    const std::int64_t d = day.issued_at_s;
    if (table && (past_weather_forecast.size() == 0 || past_weather_forecast.time_s.back() < d ||
                  past_weather_forecast.time_s.front() >= d + kDayS)) {
      return true;
    }
    Forecast f;
    ok = MakeForecast(plant, spec, params, before, table ? past_weather_forecast : Series{},
                      Series{}, day, &f, error);
    if (!ok) return false;
    const std::size_t n_before = out->by_source[s].size();
    Score(f, RegimesOf(plant, f.inputs_used), history, table, &out->by_source[s]);
    if (out->by_source[s].size() > n_before) ++out->days[s];
    return true;
  });
  return ok;
}

// ChooseOperation, keeping the persistence errors of each operation forecast
// (as ReplaySource gives them) in *by_operation.
bool CompareOperations(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                       const Series& history, const ForecastRequest& request, OperationChoice* out,
                       std::array<ForecastErrors, 2>* by_operation, std::string* error) {
  *out = OperationChoice{};
  for (int mode = 0; mode < 2; ++mode) {
    ForecastRequest r = request;
    r.operation = mode ? OperationForecast::kLearned : OperationForecast::kTypicalDay;
    (*by_operation)[mode] = ForecastErrors{};
    if (!ReplaySource(plant, spec, params, history, Series{}, r, WeatherSource::kPersistence,
                      &(*by_operation)[mode], error)) {
      return false;
    }
  }
  out->days = (*by_operation)[0].days[0];
  // The same minutes for both: those where both forecasts have Q.
  const std::vector<ForecastError>& typical = (*by_operation)[0].by_source[0];
  const std::vector<ForecastError>& learned = (*by_operation)[1].by_source[0];
  double sum[2] = {0.0, 0.0};
  std::size_t n = 0, j = 0;
  for (const ForecastError& a : typical) {
    while (j < learned.size() && learned[j].time_s < a.time_s) ++j;
    if (j == learned.size() || learned[j].time_s != a.time_s) continue;
    if (!std::isfinite(a.q_th_w) || !std::isfinite(learned[j].q_th_w)) continue;
    sum[0] += std::fabs(a.q_th_w);
    sum[1] += std::fabs(learned[j].q_th_w);
    ++n;
  }
  if (n > 0) {
    out->mae_q_th_typical_w = sum[0] / static_cast<double>(n);
    out->mae_q_th_learned_w = sum[1] / static_cast<double>(n);
    if (out->mae_q_th_learned_w < out->mae_q_th_typical_w) {
      out->chosen = OperationForecast::kLearned;
    }
  }
  return true;
}

}  // namespace

bool ReplayForecastErrors(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                          const Series& history, const Series& past_weather_forecast,
                          const ForecastRequest& request, ForecastErrors* out, std::string* error) {
  *out = ForecastErrors{};
  return ReplaySource(plant, spec, params, history, past_weather_forecast, request,
                      WeatherSource::kPersistence, out, error) &&
         ReplaySource(plant, spec, params, history, past_weather_forecast, request,
                      WeatherSource::kWeatherForecast, out, error);
}

std::string OperationChoice::Describe() const {
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "operation forecast: %s (replayed %zu days with persisted weather: MAE q_th "
                "typical day %.1f W, learned rule %.1f W)",
                chosen == OperationForecast::kLearned ? "learned rule" : "typical day", days,
                mae_q_th_typical_w, mae_q_th_learned_w);
  return buf;
}

bool ChooseOperation(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                     const Series& history, const ForecastRequest& request, OperationChoice* out,
                     std::string* error) {
  std::array<ForecastErrors, 2> by_operation;
  return CompareOperations(plant, spec, params, history, request, out, &by_operation, error);
}

// The persistence errors come from the comparison of the operation
// forecasts (the chosen one's), not from a third replay of the same days.
bool ReplayWindow(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                  const Series& history, const Series& past_weather_forecast,
                  const ForecastRequest& request, ForecastWindowStats* out, std::string* error) {
  std::array<ForecastErrors, 2> by_operation;
  if (!CompareOperations(plant, spec, params, history, request, &out->operation, &by_operation,
                         error)) {
    return false;
  }
  out->errors = std::move(by_operation[out->operation.chosen == OperationForecast::kLearned]);
  ForecastRequest replay = request;
  replay.operation = out->operation.chosen;
  return ReplaySource(plant, spec, params, history, past_weather_forecast, replay,
                      WeatherSource::kWeatherForecast, &out->errors, error);
}

std::string BandedForecast::Inputs() const {
  return forecast.inputs.Describe() + "; " + bands.note;
}

bool MakeBandedForecast(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                        const Series& history, const Series& weather_forecast,
                        const Series& operation_plan, ForecastRequest request,
                        const ForecastWindowStats& stats, BandedForecast* out, std::string* error) {
  request.operation = stats.operation.chosen;
  if (!MakeForecast(plant, spec, params, history, weather_forecast, operation_plan, request,
                    &out->forecast, error)) {
    return false;
  }
  out->bands = BandsFor(plant, out->forecast, stats.errors);
  out->bands.note = stats.operation.Describe() + "; " + out->bands.note;
  return true;
}

namespace {

// The split-conformal scale of one source's band edges for one output
// (forecast_bands.h): each issue's errors against the quantiles of the other
// issues; 1 when the scores are too few.
struct Scale {
  double lo = 1.0, hi = 1.0;
  std::size_t scores = 0;
};
std::array<Scale, 2> ConformalScales(const std::vector<ForecastError>& errors,
                                     const BandOptions& options) {
  std::set<std::int64_t> issues;
  for (const ForecastError& e : errors) issues.insert(e.issued_at_s);
  std::array<std::vector<double>, 2> above, below;  // per output
  std::array<std::size_t, 2> scored{};
  for (const std::int64_t issue : issues) {
    const std::map<std::uint32_t, Quantiles> table = QuantileTable(errors, options, issue);
    for (const ForecastError& e : errors) {
      if (e.issued_at_s != issue) continue;
      for (int o = 0; o < 2; ++o) {
        const double err = o ? e.q_th_w : e.p_el_w;
        if (!std::isfinite(err)) continue;
        const Offsets q = Lookup(table, e.regime, o == 0);
        if (std::isnan(q.lo)) continue;
        const double a = std::min(0.0, q.lo), b = std::max(0.0, q.hi);
        if (!(b > a)) continue;  // no band here (P_el at night)
        ++scored[o];
        // The scale that just reaches the error, on its side; an error on
        // the side without width can never be reached.
        if (err > 0.0) above[o].push_back(b > 0.0 ? err / b : kInfinity);
        if (err < 0.0) below[o].push_back(a < 0.0 ? err / a : kInfinity);
      }
    }
  }
  std::array<Scale, 2> scales;
  for (int o = 0; o < 2; ++o) {
    scales[o].scores = scored[o];
    if (issues.size() < 2 || scored[o] < options.min_samples) continue;
    // The scale λ with a share upper (lower) of all scored errors at or below
    // λ·b (at or above λ·a): the errors on the other side count as below.
    const auto level = [&](std::vector<double>* side, double share_outside) {
      const double n = static_cast<double>(scored[o]);
      const double inside_needed =
          n * (1.0 - share_outside) - (n - static_cast<double>(side->size()));
      if (inside_needed <= 0.0 || side->empty()) return 0.0;
      const double q = std::min(1.0, inside_needed / static_cast<double>(side->size()));
      const double v = SampleQuantile(side, q);  // sorts
      if (std::isfinite(v)) return v;
      // Beyond the errors no scale reaches: the largest that one reaches.
      const auto reachable = std::lower_bound(side->begin(), side->end(), kInfinity);
      return reachable == side->begin() ? 1.0 : *(reachable - 1);
    };
    scales[o].hi = level(&above[o], 1.0 - options.upper_quantile);
    scales[o].lo = level(&below[o], options.lower_quantile);
  }
  return scales;
}

}  // namespace

ForecastBands BandsFor(const Plant& plant, const Forecast& forecast, const ForecastErrors& errors,
                       const BandOptions& options) {
  const std::size_t n = forecast.rows.size();
  ForecastBands b;
  for (std::vector<double>* v :
       {&b.p_el_p10, &b.p_el_p50, &b.p_el_p90, &b.q_th_p10, &b.q_th_p50, &b.q_th_p90}) {
    v->assign(n, kNaN);
  }
  std::array<std::map<std::uint32_t, Quantiles>, kWeatherSources> tables;
  std::array<std::array<Scale, 2>, kWeatherSources> scales;
  std::array<bool, kWeatherSources> usable{};
  for (std::size_t s = 0; s < kWeatherSources; ++s) {
    usable[s] = errors.by_source[s].size() >= options.min_samples;
    if (!usable[s]) continue;
    tables[s] = QuantileTable(errors.by_source[s], options);
    scales[s] = ConformalScales(errors.by_source[s], options);
  }
  const std::vector<ForecastRegime> regimes = RegimesOf(plant, forecast.inputs_used);
  bool substituted = false;
  for (std::size_t h = 0; h < n; ++h) {
    std::size_t s =
        h < forecast.weather_from_forecast.size() && forecast.weather_from_forecast[h] ? 1 : 0;
    if (!usable[s]) {
      substituted = substituted || s == 1;
      s = 0;
    }
    if (!usable[s]) continue;
    ++b.rows_from[s];
    for (int o = 0; o < 2; ++o) {
      const Offsets q = Lookup(tables[s], regimes[h], o == 0);
      const double f = forecast.rows[o ? Channel::kQThW : Channel::kPElW][h];
      if (std::isnan(q.lo) || !std::isfinite(f)) continue;
      double lo = f + scales[s][o].lo * std::min(0.0, q.lo);
      double hi = f + scales[s][o].hi * std::max(0.0, q.hi);
      if (o == 0) {
        lo = std::max(0.0, lo);
        hi = std::max(0.0, hi);
      }
      const double mid = std::clamp(f + q.mid, lo, hi);
      (o ? b.q_th_p10 : b.p_el_p10)[h] = lo;
      (o ? b.q_th_p50 : b.p_el_p50)[h] = mid;
      (o ? b.q_th_p90 : b.p_el_p90)[h] = hi;
    }
  }
  char buf[240];
  b.note = "bands:";
  for (std::size_t s = 0; s < kWeatherSources; ++s) {
    std::snprintf(buf, sizeof buf, "%s %s errors of %zu days (%zu rows", s ? ";" : "",
                  WeatherSourceName(static_cast<WeatherSource>(s)), errors.days[s], b.rows_from[s]);
    b.note += buf;
    if (usable[s]) {
      std::snprintf(buf, sizeof buf, ", conformal scale P_el %.2f/%.2f, Q_u %.2f/%.2f",
                    scales[s][0].lo, scales[s][0].hi, scales[s][1].lo, scales[s][1].hi);
      b.note += buf;
    }
    b.note += ")";
  }
  if (substituted) b.note += "; weather_forecast rows banded with persistence errors";
  return b;
}

}  // namespace pvtwin
