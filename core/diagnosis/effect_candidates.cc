#include "core/diagnosis/effect_candidates.h"

#include <cmath>

#include "core/effects/effects.h"

namespace pvtwin {

std::vector<std::string> EffectNames() {
  std::vector<std::string> names;
  for (const EffectInfo& info : EffectTable()) names.emplace_back(info.name);
  return names;
}

std::vector<EffectCandidate> CandidateEffects(const ModelSpec& base, const Series& series,
                                              std::vector<SkippedEffect>* skipped) {
  std::vector<EffectCandidate> out;
  for (const EffectInfo& info : EffectTable()) {
    std::string why;
    if (!CanAddEffect(base, info.effect, series, &why)) {
      if (skipped != nullptr) skipped->push_back({std::string(info.name), why});
      continue;
    }
    out.push_back({std::string(info.name), WithEffect(base, info.effect),
                   std::string(info.explanation), std::string(info.signature)});
  }
  return out;
}

std::vector<double> CandidateSignature(const std::string& name, const Drivers& drivers,
                                       const SimOutputs& base_outputs) {
  const std::optional<Effect> effect = EffectFromName(name);
  if (!effect) return std::vector<double>(drivers.size(), std::nan(""));
  return EffectSignature(*effect, drivers, base_outputs);
}

}  // namespace pvtwin
