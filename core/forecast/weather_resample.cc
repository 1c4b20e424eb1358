#include "core/forecast/weather_resample.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/common/units.h"
#include "core/data/physical_limits.h"
#include "core/physics/clear_sky.h"
#include "core/physics/irradiance.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/solar_position.h"
#include "core/physics/wind.h"

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::int64_t kMinute = 60;

std::string Shortest(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Minute indices [first, last) of the interval [from, from + step).
std::pair<std::size_t, std::size_t> MinutesOf(const ClearSkyGrid& g, std::int64_t from,
                                              std::int64_t step) {
  const std::int64_t begin = g.time_s.front();
  const auto first = static_cast<std::size_t>((from - begin) / kMinute);
  return {first, first + static_cast<std::size_t>(step / kMinute)};
}

// The interval's value spread evenly over its minutes with the sun above the
// horizon (all minutes when there are none): the minutes' mean is the value,
// and no light falls into the minutes of the night.
void SpreadOverDaylight(const ClearSkyGrid& g, std::size_t first, std::size_t last, double value,
                        std::vector<double>* out) {
  std::size_t daylight = 0;
  for (std::size_t k = first; k < last; ++k) daylight += g.zenith_rad[k] < kPi / 2 ? 1 : 0;
  const std::size_t n = last - first;
  for (std::size_t k = first; k < last; ++k) {
    const bool up = daylight == 0 || g.zenith_rad[k] < kPi / 2;
    (*out)[k] =
        up ? value * static_cast<double>(n) / static_cast<double>(daylight == 0 ? n : daylight)
           : 0.0;
  }
}

// The most each minute of channel c can hold (see the header): its physical
// limit, and max_clear_sky_index × clear + the allowance.
std::vector<double> MinuteBounds(Channel c, const std::vector<double>& clear,
                                 const WeatherResampleOptions& options) {
  const double limit = PhysicalLimitOf(c, 0.0).hi;
  std::vector<double> bound(clear.size());
  for (std::size_t k = 0; k < clear.size(); ++k) {
    bound[k] = std::min(limit, options.max_clear_sky_index * std::max(0.0, clear[k]) +
                                   options.clear_sky_allowance_w_m2);
  }
  return bound;
}

// Lowers the minutes [first, last) of *out to their bounds and gives what was
// cut, evenly, to the minutes that may receive light (those with the sun up,
// all when none has it) and are below their bounds, until it is placed or
// every such minute is at its bound. Returns the bounds' sum over the
// receiving minutes divided by the interval's minutes: the largest mean the
// interval can keep.
double FitUnderBounds(const ClearSkyGrid& g, std::size_t first, std::size_t last,
                      const std::vector<double>& bound, std::vector<double>* out) {
  std::vector<double>& x = *out;
  bool daylight = false;
  for (std::size_t k = first; k < last; ++k) daylight = daylight || g.zenith_rad[k] < kPi / 2;
  const auto receives = [&](std::size_t k) { return !daylight || g.zenith_rad[k] < kPi / 2; };
  double capacity = 0.0, excess = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    if (receives(k)) capacity += bound[k];
    if (x[k] > bound[k]) {
      excess += x[k] - bound[k];
      x[k] = bound[k];
    }
  }
  // Each round places everything or fills at least one minute to its bound.
  for (std::size_t round = first; excess > 0.0 && round <= last; ++round) {
    std::size_t open = 0;
    for (std::size_t k = first; k < last; ++k) open += receives(k) && x[k] < bound[k] ? 1 : 0;
    if (open == 0) break;
    const double share = excess / static_cast<double>(open);
    excess = 0.0;
    for (std::size_t k = first; k < last; ++k) {
      if (!receives(k) || !(x[k] < bound[k])) continue;
      if (x[k] + share >= bound[k]) {
        excess += share - (bound[k] - x[k]);
        x[k] = bound[k];
      } else {
        x[k] += share;
      }
    }
  }
  return capacity / static_cast<double>(last - first);
}

// Interval means of channel c to minutes through the clear-sky index of
// each interval, within the minutes' bounds (see the header): the minutes'
// mean equals the interval's value wherever the bounds allow.
std::vector<double> IntervalMeansToMinutes(const ProviderWeather& in, const ClearSkyGrid& g,
                                           Channel c, const std::vector<double>& values,
                                           const std::vector<double>& shape,
                                           const std::vector<double>& bound,
                                           const WeatherResampleOptions& options,
                                           WeatherResampleSummary* summary) {
  std::vector<double> out(g.time_s.size(), kNaN);
  const auto step = static_cast<std::int64_t>(in.step_s);
  const auto offset = static_cast<std::int64_t>(in.irradiance_offset_s);
  for (std::size_t i = 0; i < in.time_s.size(); ++i) {
    if (!std::isfinite(values[i])) continue;
    const auto [first, last] = MinutesOf(g, in.time_s[i] + offset, step);
    double shape_sum = 0.0;
    for (std::size_t k = first; k < last; ++k) shape_sum += shape[k];
    const double shape_mean = shape_sum / static_cast<double>(last - first);
    const double index = values[i] / shape_mean;
    const bool flat =
        shape_mean < options.min_clear_sky_mean_w_m2 || !(index <= options.max_clear_sky_index);
    if (!flat) {
      for (std::size_t k = first; k < last; ++k) out[k] = index * shape[k];
    } else {
      if (values[i] > 0.0) ++summary->flat_intervals;
      SpreadOverDaylight(g, first, last, values[i], &out);
    }
    const double most = FitUnderBounds(g, first, last, bound, &out);
    // Above by more than rounding: the interval's energy does not fit.
    if (!(values[i] > most * (1.0 + 1e-12) + 1e-9)) continue;
    summary->above_clear_sky.push_back(
        {c, in.time_s[i] + offset, in.time_s[i] + offset + step, values[i], shape_mean, most});
    summary->above_clear_sky_rows.resize(g.time_s.size(), 0);
    for (std::size_t k = first; k < last; ++k) summary->above_clear_sky_rows[k] = 1;
  }
  return out;
}

// DHI = GHI − DNI·mean cos θ_z of each interval, within [0, GHI].
std::vector<double> DiffuseFromBeam(const ProviderWeather& in, const ClearSkyGrid& g) {
  std::vector<double> dhi(in.time_s.size(), kNaN);
  const auto step = static_cast<std::int64_t>(in.step_s);
  const auto offset = static_cast<std::int64_t>(in.irradiance_offset_s);
  for (std::size_t i = 0; i < in.time_s.size(); ++i) {
    const auto [first, last] = MinutesOf(g, in.time_s[i] + offset, step);
    double cos_sum = 0.0;
    for (std::size_t k = first; k < last; ++k) cos_sum += std::max(0.0, std::cos(g.zenith_rad[k]));
    const double beam_h = in.dni_w_m2[i] * cos_sum / static_cast<double>(last - first);
    dhi[i] = std::clamp(in.ghi_w_m2[i] - beam_h, 0.0, std::max(0.0, in.ghi_w_m2[i]));
  }
  return dhi;
}

// Linear interpolation of stamp values at each minute's middle; held for up
// to one step beyond the first and last stamp; NaN across a missing stamp.
std::vector<double> InterpolateInstants(const ProviderWeather& in, const ClearSkyGrid& g,
                                        const std::vector<double>& values) {
  std::vector<double> out(g.time_s.size(), kNaN);
  const std::size_t n = in.time_s.size();
  for (std::size_t k = 0; k < g.time_s.size(); ++k) {
    const double t = static_cast<double>(g.time_s[k]) + 30.0 - in.instant_offset_s;
    const double first = static_cast<double>(in.time_s.front());
    const double last = static_cast<double>(in.time_s.back());
    if (t <= first) {
      if (first - t <= in.step_s) out[k] = values.front();
      continue;
    }
    if (t >= last) {
      if (t - last <= in.step_s) out[k] = values.back();
      continue;
    }
    const auto j = static_cast<std::size_t>((t - first) / in.step_s);
    if (j + 1 >= n) continue;
    const double w = (t - static_cast<double>(in.time_s[j])) / in.step_s;
    out[k] = values[j] + w * (values[j + 1] - values[j]);
  }
  return out;
}

bool CheckInput(const ProviderWeather& in, std::string* error) {
  const std::size_t n = in.time_s.size();
  *error =
      "weather input: no rows, a step or offset that is not whole minutes, a step over a day, "
      "times outside 1900-2200 or a span over 400 days";
  constexpr std::int64_t kEarliest = -2208988800, kLatest = 7258118400;  // 1900, 2200
  if (n == 0 || !(in.step_s >= 60.0 && in.step_s <= 86400.0) ||
      !(std::abs(in.irradiance_offset_s) <= in.step_s) ||
      !(in.instant_offset_s >= 0.0 && in.instant_offset_s <= in.step_s) ||
      in.time_s.front() < kEarliest || in.time_s.back() > kLatest ||
      in.time_s.back() - in.time_s.front() > 400 * 86400) {
    return false;
  }
  const auto step = static_cast<std::int64_t>(in.step_s);
  if (step % kMinute != 0 || static_cast<double>(step) != in.step_s ||
      static_cast<std::int64_t>(in.irradiance_offset_s) % kMinute != 0) {
    return false;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (in.time_s[i] < kEarliest || in.time_s[i] > kLatest || in.time_s[i] % kMinute != 0 ||
        (i > 0 && in.time_s[i] - in.time_s[i - 1] != step)) {
      *error =
          "weather input: time stamps not whole minutes step_s apart at row " + std::to_string(i);
      return false;
    }
  }
  for (const std::vector<double>* v :
       {&in.gti_w_m2, &in.ghi_w_m2, &in.dhi_w_m2, &in.dni_w_m2, &in.t_amb_c, &in.wind_m_s,
        &in.dew_point_c, &in.relative_humidity_pct, &in.cloud_cover_pct, &in.t_sky_c,
        &in.lw_down_w_m2}) {
    if (!v->empty() && v->size() != n) {
      *error = "weather input: a channel's length differs from the time stamps'";
      return false;
    }
  }
  error->clear();
  return true;
}

bool HasIrradiance(const ProviderWeather& in) {
  return !in.gti_w_m2.empty() || !in.ghi_w_m2.empty();
}

// g_poa_w_m2 and g_poa_diffuse_w_m2 from 1-min GHI/DHI (isotropic sky),
// each at most the plane's bound (the diffuse at most the global).
void Transpose(const Plant& plant, const ClearSkyGrid& g, const std::vector<double>& bound,
               Series* out, WeatherResampleSummary* summary) {
  const std::vector<double>& ghi = (*out)[Channel::kGhiWM2];
  const std::vector<double>& dhi = (*out)[Channel::kDhiWM2];
  std::vector<double> poa(ghi.size(), kNaN), poa_diffuse(ghi.size(), kNaN);
  for (std::size_t k = 0; k < ghi.size(); ++k) {
    if (!std::isfinite(ghi[k]) || !std::isfinite(dhi[k])) continue;
    IsotropicSkyInput p;
    p.ghi_w_m2 = ghi[k];
    p.dhi_w_m2 = dhi[k];
    p.zenith_rad = g.zenith_rad[k];
    p.aoi_rad = g.aoi_rad[k];
    p.tilt_rad = plant.tilt_rad;
    p.ground_albedo = plant.ground_albedo;
    const PoaComponents c = TransposeIsotropicSky(p);
    poa[k] = c.global_w_m2();
    poa_diffuse[k] = c.sky_diffuse_w_m2 + c.ground_diffuse_w_m2;
    if (poa[k] > bound[k]) {
      poa[k] = bound[k];
      poa_diffuse[k] = std::min(poa_diffuse[k], poa[k]);
      ++summary->capped_poa_minutes;
    }
  }
  (*out)[Channel::kGPoaWM2] = std::move(poa);
  (*out)[Channel::kGPoaDiffuseWM2] = std::move(poa_diffuse);
}

void ResampleIrradiance(const Plant& plant, const ProviderWeather& in, const ClearSkyGrid& g,
                        const WeatherResampleOptions& options, Series* out,
                        WeatherResampleSummary* summary) {
  summary->irradiance_intervals = in.time_s.size();
  const std::vector<double> ghi_bound = MinuteBounds(Channel::kGhiWM2, g.clear_ghi_w_m2, options);
  std::vector<double> plane_clear(g.time_s.size());
  for (std::size_t k = 0; k < plane_clear.size(); ++k) {
    plane_clear[k] = std::max(g.clear_poa_w_m2[k], g.clear_ghi_w_m2[k]);
  }
  const std::vector<double> poa_bound = MinuteBounds(Channel::kGPoaWM2, plane_clear, options);
  if (!in.ghi_w_m2.empty()) {
    std::vector<double> dhi = in.dhi_w_m2;
    std::string dhi_origin = "dhi_w_m2 from diffuse_radiation";
    if (dhi.empty() && !in.dni_w_m2.empty()) {
      dhi = DiffuseFromBeam(in, g);
      dhi_origin = "dhi_w_m2 = GHI - DNI cos(zenith)";
    }
    (*out)[Channel::kGhiWM2] = IntervalMeansToMinutes(
        in, g, Channel::kGhiWM2, in.ghi_w_m2, g.clear_ghi_w_m2, ghi_bound, options, summary);
    summary->origins.push_back("ghi_w_m2 by the clear-sky index");
    if (!dhi.empty()) {
      (*out)[Channel::kDhiWM2] = IntervalMeansToMinutes(
          in, g, Channel::kDhiWM2, dhi, g.clear_ghi_w_m2, ghi_bound, options, summary);
      summary->origins.push_back(dhi_origin + " by the clear-sky index");
    }
  }
  if (!in.gti_w_m2.empty()) {
    (*out)[Channel::kGPoaWM2] = IntervalMeansToMinutes(
        in, g, Channel::kGPoaWM2, in.gti_w_m2, g.clear_poa_w_m2, poa_bound, options, summary);
    summary->origins.push_back("g_poa_w_m2 from the tilted irradiance by the clear-sky index");
  } else if (out->Has(Channel::kGhiWM2) && out->Has(Channel::kDhiWM2)) {
    Transpose(plant, g, poa_bound, out, summary);
    summary->origins.push_back("g_poa_w_m2, g_poa_diffuse_w_m2 from GHI/DHI (isotropic sky)");
  }
}

// t_sky_c and lw_down_w_m2: as given, or from the sky model.
void ResampleLongWave(const Plant& plant, const ProviderWeather& in, const ClearSkyGrid& g,
                      Series* out, WeatherResampleSummary* summary) {
  const std::size_t n = g.time_s.size();
  std::vector<double> t_sky(n, kNaN), lw(n, kNaN);
  if (!in.lw_down_w_m2.empty() || !in.t_sky_c.empty()) {
    const bool given_lw = !in.lw_down_w_m2.empty();
    const std::vector<double> v =
        InterpolateInstants(in, g, given_lw ? in.lw_down_w_m2 : in.t_sky_c);
    for (std::size_t k = 0; k < n; ++k) {
      lw[k] = given_lw ? v[k] : kStefanBoltzmannW_m2k4 * std::pow(CToK(v[k]), 4);
      t_sky[k] = given_lw ? SkyTemperatureK(v[k]) - kZeroCelsiusK : v[k];
    }
    summary->origins.push_back(given_lw ? "lw_down_w_m2 as given, t_sky_c = (L/sigma)^(1/4)"
                                        : "t_sky_c as given, lw_down_w_m2 = sigma T_sky^4");
  } else {
    const bool humidity = !in.dew_point_c.empty() || !in.relative_humidity_pct.empty();
    if (in.t_amb_c.empty() || !humidity || in.cloud_cover_pct.empty()) return;
    const std::vector<double> t_air = InterpolateInstants(in, g, in.t_amb_c);
    const bool dew = !in.dew_point_c.empty();
    const std::vector<double> wet =
        InterpolateInstants(in, g, dew ? in.dew_point_c : in.relative_humidity_pct);
    const std::vector<double> cloud = InterpolateInstants(in, g, in.cloud_cover_pct);
    for (std::size_t k = 0; k < n; ++k) {
      const double e_a_hpa = dew ? SaturationVapourPressureHpa(wet[k])
                                 : wet[k] / 100.0 * SaturationVapourPressureHpa(t_air[k]);
      const double eps = CloudySkyEmissivity(BruntClearSkyEmissivity(e_a_hpa),
                                             std::clamp(cloud[k] / 100.0, 0.0, 1.0));
      lw[k] = LongWaveOnPlaneWM2(eps, t_air[k], plant.tilt_rad);
      t_sky[k] = SkyTemperatureK(lw[k]) - kZeroCelsiusK;
    }
    summary->origins.push_back(
        std::string("lw_down_w_m2, t_sky_c from air temperature, ") +
        (dew ? "dew point" : "relative humidity") +
        " and cloud cover (Brunt 1932, cloud correction of Crawford & Duchon 1999, on the "
        "collector plane)");
  }
  (*out)[Channel::kTSkyC] = std::move(t_sky);
  (*out)[Channel::kLwDownWM2] = std::move(lw);
}

}  // namespace

ClearSkyGrid MakeClearSkyGrid(const Plant& plant, std::int64_t begin, std::int64_t end,
                              double linke_turbidity) {
  ClearSkyGrid g;
  std::vector<double> middles;
  for (std::int64_t t = begin; t < end; t += kMinute) {
    g.time_s.push_back(t);
    middles.push_back(static_cast<double>(t) + 30.0);
  }
  std::vector<SolarPosition> sun;
  ComputeSolarPositions(middles, SiteAtStandardPressure(plant), &sun);
  const std::size_t n = middles.size();
  g.zenith_rad.resize(n);
  g.aoi_rad.resize(n);
  g.clear_ghi_w_m2.resize(n);
  g.clear_dhi_w_m2.resize(n);
  g.clear_poa_w_m2.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    g.zenith_rad[k] = sun[k].zenith_rad;
    g.aoi_rad[k] = AngleOfIncidenceRad(sun[k].zenith_rad, sun[k].azimuth_rad, plant.tilt_rad,
                                       plant.azimuth_rad);
    ClearSkyInput cs;
    cs.zenith_rad = sun[k].zenith_rad;
    cs.day_of_year = DayOfYearUtc(middles[k]);
    cs.elevation_m = plant.elevation_m;
    cs.linke_turbidity = linke_turbidity;
    const ClearSkyIrradiance clear = ClearSkyIneichenPerez(cs);
    g.clear_ghi_w_m2[k] = clear.ghi_w_m2;
    g.clear_dhi_w_m2[k] = clear.dhi_w_m2;
    IsotropicSkyInput poa;
    poa.ghi_w_m2 = clear.ghi_w_m2;
    poa.dhi_w_m2 = clear.dhi_w_m2;
    poa.zenith_rad = sun[k].zenith_rad;
    poa.aoi_rad = g.aoi_rad[k];
    poa.tilt_rad = plant.tilt_rad;
    poa.ground_albedo = plant.ground_albedo;
    g.clear_poa_w_m2[k] = TransposeIsotropicSky(poa).global_w_m2();
  }
  return g;
}

bool ResampleWeatherTo1Min(const Plant& plant, const ProviderWeather& in,
                           const WeatherResampleOptions& options, Series* out,
                           WeatherResampleSummary* summary, std::string* error) {
  if (!CheckInput(in, error)) return false;
  *summary = WeatherResampleSummary{};
  const auto step = static_cast<std::int64_t>(in.step_s);
  const std::int64_t offset =
      HasIrradiance(in) ? static_cast<std::int64_t>(in.irradiance_offset_s)
                        : static_cast<std::int64_t>(in.instant_offset_s) / kMinute * kMinute;
  const std::int64_t begin = in.time_s.front() + offset;
  const std::int64_t end = in.time_s.back() + offset + (HasIrradiance(in) ? step : kMinute);
  const ClearSkyGrid g = MakeClearSkyGrid(plant, begin, end, options.linke_turbidity);

  Series result;
  result.step_s = 60.0;
  result.time_s = g.time_s;
  ResampleIrradiance(plant, in, g, options, &result, summary);
  if (!in.t_amb_c.empty()) {
    result[Channel::kTAmbC] = InterpolateInstants(in, g, in.t_amb_c);
    summary->origins.push_back("t_amb_c interpolated linearly");
  }
  if (!in.wind_m_s.empty()) {
    summary->wind_factor = WindAtHeightPowerLaw(1.0, in.wind_height_m, options.collector_height_m,
                                                options.hellmann_exponent);
    std::vector<double> wind = InterpolateInstants(in, g, in.wind_m_s);
    for (double& v : wind) v *= summary->wind_factor;
    result[Channel::kWindMS] = std::move(wind);
    summary->origins.push_back(
        "wind_m_s interpolated linearly, times " + Shortest(summary->wind_factor) +
        " (power law, alpha " + Shortest(options.hellmann_exponent) + ", " +
        Shortest(in.wind_height_m) + " m to " + Shortest(options.collector_height_m) + " m)");
  }
  ResampleLongWave(plant, in, g, &result, summary);
  summary->outside_limits = ApplyPhysicalLimits(&result, 0.0).Total();
  summary->rows = result.size();
  *out = std::move(result);
  return true;
}

}  // namespace pvtwin
