#include "core/diagnosis/effect_candidates.h"

#include <cmath>
#include <utility>

#include "core/effects/effects.h"

namespace pvtwin {

std::vector<EffectCandidate> CandidateEffects(const ModelSpec& base, const Series& series,
                                              std::vector<SkippedEffect>* skipped) {
  std::vector<EffectCandidate> out;
  for (const EffectModule* m : EffectRegistry()) {
    std::string why;
    if (!CanAddEffect(base, *m, series, &why)) {
      if (skipped != nullptr) skipped->push_back({std::string(m->name), why});
      continue;
    }
    std::vector<NamedForm> forms = DiagnosisForms(base, *m);
    const ModelSpec first = forms.front().spec;
    const std::string form = forms.front().form;
    out.push_back({std::string(m->name), first, std::move(forms), form, std::string(m->physics),
                   std::string(m->signature), m});
  }
  return out;
}

std::vector<double> CandidateSignature(const EffectCandidate& c, const Drivers& drivers,
                                       const SimOutputs& base_outputs) {
  return EffectSignature(*c.module, drivers, base_outputs);
}

}  // namespace pvtwin
