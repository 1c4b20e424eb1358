#include "core/effect_candidates.h"

#include <cmath>

#include "core/units.h"

namespace pvtwin {

namespace {

const double kNaN = std::nan("");

struct Builtin {
  const char* name;
  const char* explanation;
  const char* signature;
};

// Until the effect library (core/effects.h) lands: the effects the variant
// grammar already has.
const Builtin kBuiltins[] = {
    {"capacitance",
     "Thermal mass of the collector: the absorber and the fluid store heat, so the outputs lag "
     "irradiance changes instead of following them at once.",
     "rate of change of the in-plane irradiance"},
    {"second_node",
     "A second temperature node separates the PV laminate from the absorber/fluid, so the PV "
     "runs warmer than the fluid by an amount that grows with the absorbed heat.",
     "absorbed irradiance times the base model's node-to-inlet difference"},
    {"wind",
     "Forced convection: the front heat loss grows with wind speed, cooling the collector more "
     "when it is windy and the collector is warmer than the air.",
     "wind speed times (T_PV − T_amb) of the base model"},
    {"sky_radiation",
     "Long-wave exchange with the sky: a clear sky is much colder than the air, so the front "
     "loses heat by radiation even when the collector is at ambient temperature.",
     "T_amb − T_sky"},
    {"iam",
     "Incidence-angle modifier: more beam light is reflected at oblique incidence, so at large "
     "angles of incidence less irradiance is absorbed than the plane pyranometer reads.",
     "in-plane irradiance lost to reflection at the angle of incidence"},
    {"transport_delay",
     "Fluid residence time: the outlet sensor sees the collector's temperature with a delay, "
     "so changes of inlet temperature and irradiance appear late at the outlet.",
     "rate of change of the inlet temperature"},
};

bool HasChannels(const Series& s, const ModelSpec& spec, std::string* missing) {
  for (const InputRequirement& req : RequiredInputs(spec)) {
    bool ok = false;
    for (const std::vector<Channel>& alt : req.alternatives) {
      bool all = true;
      for (Channel c : alt) all = all && s.Has(c);
      ok = ok || all;
    }
    if (!ok) {
      *missing = "the data lack " + req.what;
      return false;
    }
  }
  return true;
}

// The model with `name` added, or false with *why.
bool AddBuiltin(const std::string& name, const ModelSpec& base, ModelSpec* out, std::string* why) {
  *out = base;
  if (name == "capacitance") {
    if (base.nodes == 1 && !base.c_pv) {
      out->c_pv = true;
    } else if (base.nodes == 2 && !base.c_coll) {
      out->c_coll = true;
    } else if (base.nodes == 2 && !base.c_pv) {
      out->c_pv = true;
    } else {
      *why = "every node already has a capacitance";
      return false;
    }
    return true;
  }
  if (name == "second_node") {
    if (base.nodes == 2) {
      *why = "the model already has two nodes";
      return false;
    }
    out->nodes = 2;
    if (base.c_pv) {  // keep the capacitance, on the collector node
      out->c_pv = false;
      out->c_coll = true;
    }
    return true;
  }
  if (name == "wind") {
    if (base.wind_paper || base.Has(Extension::kWind)) {
      *why = "already in the model";
      return false;
    }
    out->wind_paper = true;
    return true;
  }
  if (name == "sky_radiation") {
    if (base.sky) {
      *why = "already in the model";
      return false;
    }
    out->sky = true;
    return true;
  }
  if (name == "iam") {
    if (base.iam) {
      *why = "already in the model";
      return false;
    }
    out->iam = true;
    return true;
  }
  if (name == "transport_delay") {
    if (base.Has(Extension::kTransportDelay)) {
      *why = "already in the model";
      return false;
    }
    out->extensions.set(static_cast<std::size_t>(Extension::kTransportDelay));
    return true;
  }
  *why = "not in the effect library yet";
  return false;
}

// Rate of change per minute of x to the previous row (NaN at gaps).
std::vector<double> RatePerMinute(const Drivers& d, const std::vector<double>& x) {
  std::vector<double> out(d.size(), kNaN);
  for (std::size_t i = 1; i < d.size(); ++i) {
    if (d.restart[i]) continue;
    const double dt_s = static_cast<double>(d.time_s[i] - d.time_s[i - 1]);
    if (dt_s > 0.0) out[i] = (x[i] - x[i - 1]) / (dt_s / 60.0);
  }
  return out;
}

}  // namespace

std::vector<std::string> EffectNames() {
  return {"capacitance",      "second_node",     "wind",        "sky_radiation", "iam",
          "flow_dependent_u", "transport_delay", "pv_clipping", "shading",       "soiling",
          "clock_offset",     "irradiance_bias"};
}

std::vector<EffectCandidate> CandidateEffects(const ModelSpec& base, const Series& series,
                                              std::vector<SkippedEffect>* skipped) {
  std::vector<EffectCandidate> out;
  for (const std::string& name : EffectNames()) {
    const Builtin* builtin = nullptr;
    for (const Builtin& b : kBuiltins) {
      if (name == b.name) builtin = &b;
    }
    ModelSpec spec;
    std::string why;
    if (builtin == nullptr || !AddBuiltin(name, base, &spec, &why) ||
        !HasChannels(series, spec, &why)) {
      if (builtin == nullptr) why = "not in the effect library yet";
      if (skipped != nullptr) skipped->push_back({name, why});
      continue;
    }
    out.push_back({name, spec, builtin->explanation, builtin->signature});
  }
  return out;
}

std::vector<double> CandidateSignature(const std::string& name, const Drivers& d,
                                       const SimOutputs& base) {
  const std::size_t n = d.size();
  std::vector<double> out(n, kNaN);
  if (name == "capacitance") return RatePerMinute(d, d.g_poa_w_m2);
  if (name == "transport_delay") return RatePerMinute(d, d.t_in_c);
  for (std::size_t i = 0; i < n && i < base.t_pv_c.size(); ++i) {
    if (name == "second_node") {
      out[i] = d.g_abs_w_m2[i] * (base.t_coll_c[i] - d.t_in_c[i]);
    } else if (name == "wind") {
      out[i] = std::exp(d.ln_wind[i]) * (base.t_pv_c[i] - d.t_amb_c[i]);
    } else if (name == "sky_radiation") {
      out[i] = d.t_amb_c[i] - KToC(std::sqrt(std::sqrt(d.t_sky_k4[i])));
    } else if (name == "iam") {
      out[i] = d.g_poa_w_m2[i] - d.g_abs_w_m2[i];
    }
  }
  return out;
}

}  // namespace pvtwin
