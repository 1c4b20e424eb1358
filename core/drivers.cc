// PrepareDrivers: measured series → per-row model inputs (thermal_model.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/irradiance_drivers.h"
#include "core/sky_radiation.h"
#include "core/thermal_model.h"
#include "core/units.h"

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

}  // namespace

bool PrepareDrivers(const Series& s, const Plant& plant, const ModelSpec& spec, Drivers* d,
                    std::string* error) {
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
  const std::size_t n = s.size();
  if (n == 0) {
    *error = "no data rows";
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

  ComputeIrradianceDrivers(s, plant, spec, &out.g_poa_w_m2, &out.g_abs_w_m2);

  out.ln_wind.assign(n, 0.0);
  if (spec.wind_paper || spec.Has(Extension::kWind)) {
    const auto& wind = s[Channel::kWindMS];
    for (std::size_t i = 0; i < n; ++i) {
      out.ln_wind[i] = wind[i] > 0.0 ? std::log(wind[i])
                                     : (wind[i] == 0.0 || wind[i] < 0.0
                                            ? -std::numeric_limits<double>::infinity()
                                            : wind[i]);  // NaN stays NaN
    }
  }
  out.t_sky_k4.assign(n, 0.0);
  if (spec.sky) {
    const bool have_t_sky = s.Has(Channel::kTSkyC);
    for (std::size_t i = 0; i < n; ++i) {
      double t_sky_k = have_t_sky ? CToK(s[Channel::kTSkyC][i]) : std::nan("");
      if (std::isnan(t_sky_k) && s.Has(Channel::kLwDownWM2)) {
        t_sky_k = SkyTemperatureK(s[Channel::kLwDownWM2][i]);
      }
      out.t_sky_k4[i] = t_sky_k * t_sky_k * t_sky_k * t_sky_k;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
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
                                [](double v) { return std::isfinite(v); });
  }
  *d = std::move(out);
  return true;
}

}  // namespace pvtwin
