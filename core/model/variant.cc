#include "core/model/variant.h"

#include <array>
#include <utility>

namespace pvtwin {

namespace {

struct ExtensionName {
  Extension extension;
  std::string_view name;
};

constexpr std::array<ExtensionName, kNumExtensions> kExtensionNames = {{
    {Extension::kWind, "wind"},
    {Extension::kTransportDelay, "transport_delay"},
    {Extension::kFlowDependentU, "flow_dependent_u"},
    {Extension::kPvClipping, "pv_clipping"},
    {Extension::kShading, "shading"},
    {Extension::kSoiling, "soiling"},
    {Extension::kClockOffset, "clock_offset"},
    {Extension::kIrradianceBias, "irradiance_bias"},
}};

bool ConsumePrefix(std::string_view* s, std::string_view prefix) {
  if (s->substr(0, prefix.size()) != prefix) return false;
  s->remove_prefix(prefix.size());
  return true;
}

bool ParseBase(std::string_view base, ModelSpec* spec, std::string* error) {
  std::string_view s = base;
  if (ConsumePrefix(&s, "1N")) {
    spec->nodes = 1;
    if (ConsumePrefix(&s, "1Cpv") || ConsumePrefix(&s, "1C")) spec->c_pv = true;
  } else if (ConsumePrefix(&s, "2N")) {
    spec->nodes = 2;
    if (ConsumePrefix(&s, "1Cpv")) {
      spec->c_pv = true;
    } else if (ConsumePrefix(&s, "1Ccol")) {
      spec->c_coll = true;
    } else if (ConsumePrefix(&s, "2C")) {
      spec->c_pv = spec->c_coll = true;
    } else if (s.substr(0, 2) == "1C") {
      *error = "'" + std::string(base) +
               "': a two-node model needs the capacitance's node: 1Cpv or 1Ccol";
      return false;
    }
  } else {
    *error = "'" + std::string(base) + "': a variant starts with 1N or 2N";
    return false;
  }
  if (ConsumePrefix(&s, "w")) spec->wind_paper = true;
  if (ConsumePrefix(&s, "r")) spec->sky = true;
  if (ConsumePrefix(&s, "I")) spec->iam = true;
  if (!s.empty()) {
    *error = "'" + std::string(base) + "': unexpected '" + std::string(s) +
             "' (grammar: {1,2}N[1C|1Cpv|1Ccol|2C][w][r][I], e.g. 2N1Ccolwr)";
    return false;
  }
  return true;
}

bool ParseEffect(std::string_view effect, ModelSpec* spec, std::string* error) {
  if (effect == "sky_radiation") {
    spec->sky = true;
    return true;
  }
  if (effect == "iam") {
    spec->iam = true;
    return true;
  }
  if (effect == "capacitance") {
    if (spec->nodes == 1) {
      spec->c_pv = true;
    } else if (!spec->c_coll) {
      spec->c_coll = true;
    } else {
      spec->c_pv = true;
    }
    return true;
  }
  if (effect == "second_node") {
    spec->nodes = 2;
    return true;
  }
  for (const ExtensionName& e : kExtensionNames) {
    if (e.name == effect) {
      spec->extensions.set(static_cast<std::size_t>(e.extension));
      return true;
    }
  }
  std::string known;
  for (const ExtensionName& e : kExtensionNames) known += std::string(e.name) + ", ";
  *error = "unknown effect '" + std::string(effect) + "' (known: " + known +
           "capacitance, second_node, sky_radiation, iam)";
  return false;
}

}  // namespace

bool ParseVariant(std::string_view name, ModelSpec* spec, std::string* error) {
  ModelSpec out;
  const std::size_t plus = name.find('+');
  if (!ParseBase(name.substr(0, plus), &out, error)) return false;
  std::string_view rest = plus == std::string_view::npos ? "" : name.substr(plus + 1);
  while (plus != std::string_view::npos) {
    const std::size_t next = rest.find('+');
    const std::string_view effect = rest.substr(0, next);
    if (effect.empty()) {
      *error = "'" + std::string(name) + "': empty effect name after '+'";
      return false;
    }
    if (!ParseEffect(effect, &out, error)) return false;
    if (next == std::string_view::npos) break;
    rest.remove_prefix(next + 1);
  }
  if (out.wind_paper && out.Has(Extension::kWind)) {
    *error = "'" + std::string(name) +
             "': 'w' (paper's wind form) and '+wind' (physical form) exclude each other";
    return false;
  }
  *spec = out;
  return true;
}

std::string ModelSpec::Name() const {
  std::string name = nodes == 1 ? "1N" : "2N";
  if (nodes == 1) {
    if (c_pv) name += "1C";
  } else if (c_pv && c_coll) {
    name += "2C";
  } else if (c_pv) {
    name += "1Cpv";
  } else if (c_coll) {
    name += "1Ccol";
  }
  if (wind_paper) name += "w";
  if (sky) name += "r";
  if (iam) name += "I";
  for (const ExtensionName& e : kExtensionNames) {
    if (Has(e.extension)) name += "+" + std::string(e.name);
  }
  return name;
}

const std::vector<std::string>& PaperVariants() {
  static const std::vector<std::string> kVariants = {
      "1N", "1Nwr", "1N1C", "1N1Cwr", "2Nwr", "2N1Cpvwr", "2N1Ccolwr", "2N1CcolwrI", "2N2Cwr"};
  return kVariants;
}

std::bitset<kNumParams> UsedParams(const ModelSpec& spec) {
  std::bitset<kNumParams> used;
  auto use = [&used](Param p) { used.set(static_cast<std::size_t>(p)); };
  for (Param p :
       {Param::kAreaM2, Param::kEtaPvRef, Param::kFTh, Param::kUFrontWM2K, Param::kUBackWM2K,
        Param::kR0FluidM2KW, Param::kR1Fluid, Param::kPvTempCoeffPerK, Param::kPvIrrCoeffM2W}) {
    use(p);
  }
  if (spec.nodes == 2) use(Param::kUCollWM2K);
  if (spec.c_pv) use(Param::kCPvJM2K);
  if (spec.c_coll) use(Param::kCCollJM2K);
  if (spec.sky) use(Param::kEpsPvt);
  if (spec.wind_paper) {
    use(Param::kRRefWind);
    use(Param::kNWind);
  }
  if (spec.Has(Extension::kWind)) {
    use(Param::kUWindWM2K);
    use(Param::kNWind);
  }
  if (spec.Has(Extension::kTransportDelay)) {
    use(Param::kTransportDelayS);
    use(Param::kUPipeWM2K);
  }
  if (spec.Has(Extension::kFlowDependentU)) use(Param::kNFlow);
  if (spec.Has(Extension::kPvClipping)) use(Param::kPLimitWM2);
  if (spec.Has(Extension::kShading)) {
    for (Param p : {Param::kShadeAzimuthRad, Param::kShadeWidthRad, Param::kShadeElevationRad,
                    Param::kShadeMismatch}) {
      use(p);
    }
  }
  if (spec.Has(Extension::kSoiling)) use(Param::kSoilingPerDay);
  if (spec.Has(Extension::kClockOffset)) use(Param::kClockOffsetS);
  // irradiance_bias: k is calibrated from the two irradiance sources when the
  // drivers are prepared (Drivers::irradiance_bias), not by the fit: P_el and
  // Q_u alone cannot separate it from η_PV·F_th (see effects.cc).
  return used;
}

std::bitset<kNumParams> DefaultFreeParams(const ModelSpec& spec) {
  std::bitset<kNumParams> free = UsedParams(spec);
  free.reset(static_cast<std::size_t>(Param::kAreaM2));
  free.reset(static_cast<std::size_t>(Param::kPvTempCoeffPerK));
  free.reset(static_cast<std::size_t>(Param::kPvIrrCoeffM2W));
  return free;
}

std::vector<InputRequirement> RequiredInputs(const ModelSpec& spec) {
  using C = Channel;
  std::vector<InputRequirement> req = {
      {"fluid inlet temperature", {{C::kTInC}}},
      {"fluid mass flow", {{C::kMdotKgS}}},
      {"ambient temperature", {{C::kTAmbC}}},
  };
  if (spec.iam) {
    req.push_back({"beam/diffuse irradiance (I)",
                   {{C::kGPoaWM2, C::kGPoaDiffuseWM2}, {C::kGhiWM2, C::kDhiWM2}}});
  } else {
    req.push_back({"irradiance in the collector plane", {{C::kGPoaWM2}, {C::kGhiWM2, C::kDhiWM2}}});
  }
  if (spec.wind_paper || spec.Has(Extension::kWind)) {
    req.push_back({"wind speed (w)", {{C::kWindMS}}});
  }
  if (spec.sky) req.push_back({"sky temperature (r)", {{C::kTSkyC}, {C::kLwDownWM2}}});
  if (spec.Has(Extension::kShading)) {
    req.push_back({"beam/diffuse irradiance (shading)",
                   {{C::kGPoaWM2, C::kGPoaDiffuseWM2}, {C::kGhiWM2, C::kDhiWM2}}});
  }
  if (spec.Has(Extension::kIrradianceBias)) {
    req.push_back({"plane-of-array and a second irradiance source (irradiance_bias)",
                   {{C::kGPoaWM2, C::kGhiWM2, C::kDhiWM2}}});
  }
  return req;
}

}  // namespace pvtwin
