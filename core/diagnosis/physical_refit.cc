// Fits of the diagnosis within physical ranges (issue 52, item 3): a
// parameter at a bound of the paper's Table 3 range gets the hull of that
// range and its physical range (core/common/physical_ranges.h) before the
// fit counts. See IdentifyInRanges (stages.h).
#include <algorithm>
#include <cmath>

#include "core/common/physical_ranges.h"
#include "core/common/text.h"
#include "core/diagnosis/stages.h"

namespace pvtwin {

namespace {

std::string Significant(double x) { return SignificantDigits(x, 3); }

}  // namespace

std::string RefittedSentence(const RefittedParam& r) {
  const ParamInfo& info = Info(r.param);
  return std::string(info.symbol) + " at its Table 3 bound " + Significant(r.table_bound) +
         ", re-fitted in " + Significant(r.lower) + " to " + Significant(r.upper) +
         " (its physical range): " + Significant(r.value) +
         (r.used ? "" : ", not used: no lower training cost");
}

namespace diagnosis_stages {

namespace {

// Sets (or replaces) the search range of p in *ident to its widened one.
void Widen(Param p, const Plant& plant, IdentOptions* ident) {
  std::erase_if(ident->search_ranges, [p](const ParamInfo& r) { return r.param == p; });
  ident->search_ranges.push_back(WidenedInfo(p, plant));
}

}  // namespace

RangedFit IdentifyInRanges(const Drivers& drivers, const Measurements& meas,
                           const ParamVector& start, const DiagnosisOptions& options) {
  RangedFit out;
  const Plant& plant = drivers.plant;
  IdentOptions ident = options.ident;
  const std::bitset<kNumParams> used = UsedParams(drivers.spec);
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const auto p = static_cast<Param>(i);
    const ParamInfo table = ResolvedInfo(p, plant);
    if (used.test(i) && (start[i] < table.lower || start[i] > table.upper)) {
      Widen(p, plant, &ident);
    }
  }
  out.fit = Identify(drivers, meas, start, ident);
  if (!options.refit_in_physical_ranges || !out.fit.ok) return out;
  IdentOptions wide = ident;
  for (const ParamEstimate& e : out.fit.estimates) {
    if (!e.free || !e.at_bound) continue;
    const ParamInfo widened = WidenedInfo(e.param, plant);
    const bool at_lower = std::fabs(e.value - e.lower) <= std::fabs(e.value - e.upper);
    const bool extends = at_lower ? widened.lower < e.lower : widened.upper > e.upper;
    if (!extends) continue;
    Widen(e.param, plant, &wide);
    RefittedParam r;
    r.param = e.param;
    r.table_bound = at_lower ? e.lower : e.upper;
    r.lower = widened.lower;
    r.upper = widened.upper;
    out.refitted.push_back(r);
  }
  if (out.refitted.empty()) return out;
  IdentSummary refit = Identify(drivers, meas, out.fit.params, wide);
  const bool better = refit.ok && refit.final_cost_w_m2 <= out.fit.final_cost_w_m2;
  for (RefittedParam& r : out.refitted) {
    r.value = ParamOf(refit.params, r.param);
    r.used = better;
  }
  if (better) {
    refit.runtime_s += out.fit.runtime_s;
    out.fit = std::move(refit);
  }
  return out;
}

}  // namespace diagnosis_stages

}  // namespace pvtwin
