// The candidate effects of the gap diagnosis: which catalogued effects
// (doc/contracts.md's vocabulary) can be added to a model, the model with the effect
// added, and the per-row signature its residual evidence is correlated with.
// A thin layer over the effect library (core/effects/effects.h: the
// registry, CanAddEffect with the data's channels, WithEffect,
// EffectSignature): the diagnosis asks a candidate's module, never its name.
#pragma once

#include <string>
#include <vector>

#include "core/common/series.h"
#include "core/effects/effects.h"
#include "core/model/thermal_model.h"
#include "core/model/variant.h"

namespace pvtwin {

struct EffectCandidate {
  std::string name;  // e.g. "pv_clipping"
  ModelSpec spec;    // the model with the effect added
  // Every form of the effect to fit (DiagnosisForms; spec is the first's);
  // the trial scores each on the held-out days and sets spec and form to the
  // one with the lower held-out objective.
  std::vector<NamedForm> forms;
  std::string form;  // the name of spec's form
  std::string explanation;               // physics, one paragraph
  std::string signature;                 // what the residual evidence is correlated with
  const EffectModule* module = nullptr;  // what else differs between effects is asked here
};

struct SkippedEffect {
  std::string name;
  std::string why;  // e.g. "already in the model", "needs ghi_w_m2 and dhi_w_m2"
};

// The effects that can be added to `base` with the channels `series` has;
// the others go to *skipped (may be null) with the reason.
std::vector<EffectCandidate> CandidateEffects(const ModelSpec& base, const Series& series,
                                              std::vector<SkippedEffect>* skipped);

// Signature values of the candidate's effect per row of `drivers` (built for
// the model with the effect), with the base model's outputs on the same
// rows; NaN where undefined.
std::vector<double> CandidateSignature(const EffectCandidate& candidate, const Drivers& drivers,
                                       const SimOutputs& base_outputs);

}  // namespace pvtwin
