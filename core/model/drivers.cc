// PrepareDrivers: measured series → per-row model inputs (thermal_model.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <string>

#include "core/common/calendar.h"
#include "core/common/threads.h"
#include "core/common/units.h"
#include "core/model/irradiance_drivers.h"
#include "core/model/thermal_model.h"
#include "core/physics/iam.h"
#include "core/physics/irradiance.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/solar_position.h"

namespace pvtwin {

namespace {

bool AllPresent(const Series& s, const std::vector<Channel>& channels) {
  return std::all_of(channels.begin(), channels.end(), [&s](Channel c) { return s.Has(c); });
}

std::string ChannelList(const std::vector<Channel>& channels) {
  std::string out;
  for (Channel c : channels) out += (out.empty() ? "" : " + ") + std::string(ChannelName(c));
  return out;
}

// The raw drivers of the effect modules (core/common/model_data.h, Drivers): sun
// geometry at the row middles, measured wind and sky temperature, the beam
// part of the absorbed irradiance, the transposed GHI/DHI and the soiling
// clock. Reads d->aoi_rad (AoiAtRows), set before.
void FillEffectDrivers(const Series& s, const Plant& plant, const ModelSpec& spec,
                       std::span<const SolarPosition> sun, Drivers* d) {
  const std::size_t n = s.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  d->wind_m_s = s.Has(Channel::kWindMS) ? s[Channel::kWindMS] : std::vector<double>(n, nan);
  d->t_sky_c = SkyTemperaturesC(s, plant, &d->sky_note, &d->sky_used);
  d->sun_azimuth_rad.resize(n);
  d->sun_elevation_rad.resize(n);
  d->g_beam_w_m2.assign(n, nan);
  d->g_ref_w_m2.assign(n, nan);
  const bool have_horizontal = s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2);
  // Row-local: split between two threads for a long series (ForRowHalves).
  ForRowHalves(n, kRowsToSplit, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      d->sun_azimuth_rad[i] = sun[i].azimuth_rad;
      d->sun_elevation_rad[i] = sun[i].elevation_rad;
      const double aoi_rad = d->aoi_rad[i];
      double beam_w_m2 = nan;
      if (have_horizontal) {
        const PoaComponents poa = TransposeRowIsotropicSky(s, plant, i, sun[i], aoi_rad);
        d->g_ref_w_m2[i] = poa.global_w_m2();
        beam_w_m2 = poa.beam_w_m2;
      }
      const double g_poa = s.At(Channel::kGPoaWM2, i);
      const double diffuse = s.At(Channel::kGPoaDiffuseWM2, i);
      if (!std::isnan(g_poa) && !std::isnan(diffuse)) beam_w_m2 = std::max(0.0, g_poa - diffuse);
      if (spec.iam) beam_w_m2 *= IamSoukaSafwat(aoi_rad, plant.iam_b0);
      d->g_beam_w_m2[i] = beam_w_m2;
    }
  });
  SetCleaningTimes({}, d);
}

}  // namespace

void RowGroups::Add(std::size_t end, const std::vector<double>& row_dt_s) {
  if (begin.empty()) begin.push_back(0);
  double dt = 0.0;
  for (std::size_t k = begin.back(); k < end; ++k) dt += row_dt_s[k];
  begin.push_back(end);
  dt_s.push_back(dt);
}

void RowGroups::Means(const std::vector<double>& v, const std::vector<double>& row_dt_s,
                      std::vector<double>* out) const {
  out->resize(size());
  for (std::size_t g = 0; g < size(); ++g) {
    double acc = 0.0;
    for (std::size_t k = begin[g]; k < begin[g + 1]; ++k) acc += v[k] * row_dt_s[k];
    (*out)[g] = acc / dt_s[g];
  }
}

void RowGroups::Middles(const std::vector<double>& v, std::vector<double>* out) const {
  out->resize(size());
  for (std::size_t g = 0; g < size(); ++g) (*out)[g] = v[begin[g] + (begin[g + 1] - begin[g]) / 2];
}

void CoarsenEffectDrivers(const Drivers& d, const RowGroups& groups, Drivers* coarse) {
  auto mean = [&](const std::vector<double>& v, std::vector<double>* out) {
    groups.Means(v, d.dt_s, out);
  };
  mean(d.wind_m_s, &coarse->wind_m_s);
  mean(d.t_sky_c, &coarse->t_sky_c);
  groups.Middles(d.sun_azimuth_rad, &coarse->sun_azimuth_rad);
  groups.Middles(d.sun_elevation_rad, &coarse->sun_elevation_rad);
  groups.Middles(d.aoi_rad, &coarse->aoi_rad);
  mean(d.g_beam_w_m2, &coarse->g_beam_w_m2);
  mean(d.g_ref_w_m2, &coarse->g_ref_w_m2);
  mean(d.days_since_clean, &coarse->days_since_clean);
  if (d.soiling_recovered.size() == d.size()) {
    mean(d.soiling_recovered, &coarse->soiling_recovered);
  }
  coarse->irradiance_bias = d.irradiance_bias;
  Drivers::IamParts& parts = coarse->iam_parts;
  if (d.iam_parts.beam_w_m2.size() == d.size()) {
    mean(d.iam_parts.beam_w_m2, &parts.beam_w_m2);
    mean(d.iam_parts.sky_w_m2, &parts.sky_w_m2);
    mean(d.iam_parts.ground_w_m2, &parts.ground_w_m2);
    groups.Middles(d.iam_parts.beam_excess, &parts.beam_excess);
    groups.Middles(d.iam_parts.paper_k_beam, &parts.paper_k_beam);
  }
}

std::vector<Cleaning> DetectCleanings(const Series& s, const Plant& plant) {
  if (!s.Has(Channel::kPElW) || !s.Has(Channel::kGPoaWM2) || !s.Has(Channel::kTAmbC) ||
      s.size() == 0) {
    return {};
  }
  constexpr double kBrightWM2 = 500.0;
  constexpr std::size_t kMinRows = 20;
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  const std::vector<double>& p_el = s[Channel::kPElW];
  const std::vector<double>& g_poa = s[Channel::kGPoaWM2];
  const std::vector<double>& t_amb = s[Channel::kTAmbC];
  std::vector<std::int64_t> day_start;
  std::vector<double> index;  // PI per day with enough bright rows
  std::vector<double> ratios;
  auto close_day = [&](std::int64_t start) {
    if (ratios.size() >= kMinRows) {
      std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
      day_start.push_back(start);
      index.push_back(ratios[ratios.size() / 2]);
    }
    ratios.clear();
  };
  std::int64_t current = SolarDayStartS(s.time_s[0], offset_s);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int64_t day = SolarDayStartS(s.time_s[i], offset_s);
    if (day != current) {
      close_day(current);
      current = day;
    }
    const double g = g_poa[i];
    if (!(g >= kBrightWM2) || !(p_el[i] > 0.0) || !std::isfinite(t_amb[i]) ||
        s.At(Channel::kValid, i) == 0.0) {
      continue;
    }
    const double t_pv_c = s.At(Channel::kTPvC, i);
    const double t_module_c = std::isfinite(t_pv_c) ? t_pv_c : t_amb[i] + 0.025 * g;
    ratios.push_back(p_el[i] /
                     (g * (1.0 + plant.pv_temp_coeff_per_k * (t_module_c - plant.pv_t_ref_c))));
  }
  close_day(current);
  if (index.size() < 6) return {};
  std::vector<double> change(index.size() - 1);
  for (std::size_t k = 1; k < index.size(); ++k) change[k - 1] = std::log(index[k] / index[k - 1]);
  std::vector<double> sorted = change;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (double& x : sorted) x = std::fabs(x - median);
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double sigma = 1.4826 * sorted[sorted.size() / 2];
  const double threshold = std::max(std::log(1.02), 4.0 * sigma);
  std::vector<Cleaning> out;
  for (std::size_t k = 1; k < index.size(); ++k) {
    if (change[k - 1] <= threshold) continue;
    if (k + 1 < index.size() && std::log(index[k + 1] / index[k - 1]) < 0.5 * change[k - 1]) {
      continue;  // undone the next day: a good day, not a cleaning
    }
    out.push_back({day_start[k], index[k] / index[k - 1] - 1.0});
  }
  return out;
}

void SetCleanings(const std::vector<Cleaning>& cleanings, Drivers* d) {
  d->soiling_recovered.assign(d->size(), 0.0);
  for (const Cleaning& c : cleanings) {
    for (std::size_t i = 0; i < d->size(); ++i) {
      if (d->time_s[i] >= c.time_s) d->soiling_recovered[i] += c.recovered;
    }
  }
}

void SetCleaningTimes(const std::vector<std::int64_t>& cleaning_times_s, Drivers* d) {
  std::vector<std::int64_t> cleanings = cleaning_times_s;
  std::sort(cleanings.begin(), cleanings.end());
  const std::size_t n = d->size();
  d->days_since_clean.resize(n);
  if (n == 0) return;
  std::int64_t last_clean_s = d->time_s[0];
  std::size_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (next < cleanings.size() && cleanings[next] <= d->time_s[i]) {
      last_clean_s = std::max(last_clean_s, cleanings[next]);
      ++next;
    }
    d->days_since_clean[i] = static_cast<double>(d->time_s[i] - last_clean_s) / 86400.0;
  }
}

namespace {

// False with *error naming each input `spec` needs that the series lacks,
// or when it has no rows.
bool HasInputsFor(const Series& s, const ModelSpec& spec, std::string* error) {
  std::string missing;
  for (const InputRequirement& req : RequiredInputs(spec)) {
    const bool ok = std::any_of(req.alternatives.begin(), req.alternatives.end(),
                                [&s](const auto& set) { return AllPresent(s, set); });
    if (ok) continue;
    std::string options;
    for (const auto& set : req.alternatives) {
      options += (options.empty() ? "" : " or ") + ChannelList(set);
    }
    missing += (missing.empty() ? "" : "; ") + req.what + " (" + options + ")";
  }
  if (!missing.empty()) {
    *error = "variant " + spec.Name() + " needs columns the data lacks: " + missing;
    return false;
  }
  if (s.size() == 0) {
    *error = "no data rows";
    return false;
  }
  return true;
}

// PrepareDrivers of a series whose inputs HasInputsFor has checked.
bool PrepareCheckedDrivers(const Series& s, const Plant& plant, const ModelSpec& spec,
                           std::span<const SolarPosition> sun, Drivers* d, std::string* error) {
  const std::size_t n = s.size();
  if (sun.size() != n) {
    *error = std::to_string(sun.size()) + " sun positions for " + std::to_string(n) + " rows";
    return false;
  }
  Drivers out;
  out.spec = spec;
  out.plant = plant;
  out.time_s = s.time_s;
  const double step_s = s.step_s > 0.0 ? s.step_s : 60.0;
  // A gap longer than this restarts the states (paper 2.2 initialisation).
  const double max_gap_s = std::max(3.0 * step_s, 600.0);
  out.dt_s.resize(n);
  out.restart.assign(n, 0);
  out.usable.assign(n, 1);
  out.restart[0] = 1;
  for (std::size_t i = 0; i < n; ++i) {
    const double to_next = i + 1 < n ? static_cast<double>(s.time_s[i + 1] - s.time_s[i]) : step_s;
    if (to_next > max_gap_s) {
      out.dt_s[i] = step_s;
      if (i + 1 < n) out.restart[i + 1] = 1;
    } else {
      out.dt_s[i] = to_next;
    }
  }

  out.t_in_c = s[Channel::kTInC];
  out.mdot_kg_s = s[Channel::kMdotKgS];
  out.t_amb_c = s[Channel::kTAmbC];
  out.t_back_c = s.Has(Channel::kTBackC) ? s[Channel::kTBackC] : s[Channel::kTAmbC];
  for (std::size_t i = 0; i < n; ++i) {
    // T_back = T_amb where the back temperature is not measured (free-standing field).
    if (std::isnan(out.t_back_c[i])) out.t_back_c[i] = out.t_amb_c[i];
    // Paper Table 1: small negative flows mean no flow.
    if (out.mdot_kg_s[i] < 0.0) out.mdot_kg_s[i] = 0.0;
  }

  out.capacity_flow_w_k.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.capacity_flow_w_k[i] = out.mdot_kg_s[i] * plant.fluid_cp_j_kgk;
  }

  out.aoi_rad = AoiAtRows(s, plant, sun);
  ComputeIrradianceDrivers(s, plant, spec, sun, out.aoi_rad, &out.g_poa_w_m2, &out.g_abs_w_m2,
                           &out.iam_parts);
  FillEffectDrivers(s, plant, spec, sun, &out);
  SetCleanings(DetectCleanings(s, plant), &out);
  for (const ModelExtension* e : spec.extensions) {
    if (e->prepare_drivers != nullptr && !e->prepare_drivers(s, &out, error)) return false;
  }

  out.ln_wind.assign(n, 0.0);
  out.t_sky_k4.assign(n, 0.0);
  const std::vector<double>* wind = spec.ReadsWind() ? &s[Channel::kWindMS] : nullptr;
  // Row-local: split between two threads for a long series (ForRowHalves).
  ForRowHalves(n, kRowsToSplit, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (wind != nullptr) {
        const double v = (*wind)[i];
        out.ln_wind[i] = v > 0.0 ? std::log(v)
                                 : (v == 0.0 || v < 0.0 ? -std::numeric_limits<double>::infinity()
                                                        : v);  // NaN stays NaN
      }
      if (spec.sky) {
        const double t_sky_k = CToK(out.t_sky_c[i]);
        out.t_sky_k4[i] = t_sky_k * t_sky_k * t_sky_k * t_sky_k;
      }
      const double inputs[] = {
          out.t_in_c[i],
          out.mdot_kg_s[i],
          out.t_amb_c[i],
          out.t_back_c[i],
          out.g_poa_w_m2[i],
          out.g_abs_w_m2[i],
          out.ln_wind[i] == -std::numeric_limits<double>::infinity() ? 0.0 : out.ln_wind[i],
          out.t_sky_k4[i]};
      out.usable[i] = std::all_of(std::begin(inputs), std::end(inputs),
                                  [](double x) { return std::isfinite(x); });
    }
  });
  *d = std::move(out);
  return true;
}

}  // namespace

// The inputs are checked before the sun is computed: a series that lacks a
// column fails without the positions of all its rows.
bool PrepareDrivers(const Series& s, const Plant& plant, const ModelSpec& spec, Drivers* d,
                    std::string* error) {
  if (!HasInputsFor(s, spec, error)) return false;
  return PrepareCheckedDrivers(s, plant, spec, SunAtRowMiddles(s, plant), d, error);
}

bool PrepareDrivers(const Series& s, const Plant& plant, const ModelSpec& spec,
                    std::span<const SolarPosition> sun, Drivers* d, std::string* error) {
  if (!HasInputsFor(s, spec, error)) return false;
  return PrepareCheckedDrivers(s, plant, spec, sun, d, error);
}

double MeasuredSkyTemperatureC(const Series& s, std::size_t i) {
  const double t_sky_c = s.At(Channel::kTSkyC, i);
  if (!std::isnan(t_sky_c) || !s.Has(Channel::kLwDownWM2)) return t_sky_c;
  return KToC(SkyTemperatureK(s[Channel::kLwDownWM2][i]));
}

namespace {

// The clear-sky estimate of row i, °C: Berdahl & Martin from the dew point
// where the row has a relative humidity (*from_dew_point), else Swinbank.
double EstimatedSkyTemperatureC(const Series& s, const Plant& plant, std::size_t i,
                                bool* from_dew_point) {
  const double t_air_c = s.At(Channel::kTAmbC, i);
  const double t_dew_c = DewPointC(t_air_c, s.At(AirChannel::kRhPct, i));
  *from_dew_point = std::isfinite(t_dew_c);
  if (!*from_dew_point) return KToC(SwinbankSkyTemperatureK(CToK(t_air_c)));
  // Hours from local mean solar midnight at the row's middle.
  const double utc_hour = static_cast<double>(s.time_s[i]) / 3600.0 + 0.5 * s.step_s / 3600.0;
  const double solar_hour = std::fmod(utc_hour + RadToDeg(plant.longitude_rad) / 15.0, 24.0);
  double p_air_hpa = s.At(AirChannel::kPAirHpa, i);
  if (!(p_air_hpa >= 300.0 && p_air_hpa <= 1100.0)) p_air_hpa = std::nan("");
  const double eps_clear = BerdahlMartinClearSkyEmittance(t_dew_c, solar_hour, p_air_hpa);
  return KToC(SkyTemperatureFromEmittanceK(eps_clear, CToK(t_air_c)));
}

}  // namespace

std::vector<double> SkyTemperaturesC(const Series& s, const Plant& plant, std::string* note,
                                     SkyUsed* used) {
  const std::size_t n = s.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (note != nullptr) note->clear();
  std::vector<double> measured(n, nan), estimated(n, nan);
  std::vector<std::uint8_t> dew(n, 0);
  ForRowHalves(n, kRowsToSplit, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      measured[i] = MeasuredSkyTemperatureC(s, i);
      bool from_dew_point = false;
      estimated[i] = EstimatedSkyTemperatureC(s, plant, i, &from_dew_point);
      dew[i] = from_dew_point ? 1 : 0;
    }
  });
  const auto dew_rows = static_cast<std::size_t>(std::count(dew.begin(), dew.end(), 1));
  const SkyUsed estimate = dew_rows > 0 ? SkyUsed::kDewPoint : SkyUsed::kAirTemperature;
  std::string how =
      "the sky temperature is estimated from the air temperature (Swinbank 1963)";
  if (dew_rows > 0) {
    how = "the sky temperature is estimated from the air temperature and dew point (clear-sky "
          "emittance of Berdahl & Martin 1984 with the hour and pressure corrections of Martin "
          "& Berdahl 1984; dew point from rh_pct by Magnus with Alduchov & Eskridge 1996) on " +
          std::to_string(dew_rows) + " of " + std::to_string(n) + " rows" +
          (dew_rows < n ? ", from the air temperature alone (Swinbank 1963) on the rest" : "");
  }
  if (used != nullptr) *used = SkyUsed::kMeasured;
  if (plant.sky == SkySource::kMeasured) return measured;
  if (plant.sky == SkySource::kEstimated) {
    if (note != nullptr) *note = how + " as [plant] sky = \"estimated\" asks";
    if (used != nullptr) *used = estimate;
    return estimated;
  }
  const Channel sun = s.Has(Channel::kGPoaWM2) ? Channel::kGPoaWM2 : Channel::kGhiWM2;
  if (!s.Has(sun)) return measured;
  std::vector<double> excess;
  for (std::size_t i = 0; i < n; ++i) {
    const double t_amb = s.At(Channel::kTAmbC, i);
    if (s[sun][i] >= 600.0 && std::isfinite(measured[i]) && std::isfinite(t_amb)) {
      excess.push_back(measured[i] - t_amb);
    }
  }
  const auto warmer = std::count_if(excess.begin(), excess.end(), [](double e) { return e > 2.0; });
  if (excess.size() < 30 || 2 * static_cast<std::size_t>(warmer) <= excess.size()) return measured;
  std::nth_element(excess.begin(), excess.begin() + excess.size() / 2, excess.end());
  if (note != nullptr) {
    char text[256];
    std::snprintf(text, sizeof(text),
                  "the long-wave channel is implausible: it puts the sky more than 2 K above the "
                  "air on %zu of %zu rows in full sun (median %+.1f K); ",
                  static_cast<std::size_t>(warmer), excess.size(), excess[excess.size() / 2]);
    *note = text + how + " instead ([plant] sky = \"measured\" keeps the channel)";
  }
  if (used != nullptr) *used = estimate;
  return estimated;
}

}  // namespace pvtwin
