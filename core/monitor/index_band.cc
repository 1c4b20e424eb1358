#include "core/monitor/index_band.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace pvtwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::int64_t kDayS = 86400;
constexpr double kZ90 = 1.2815515655446004;  // Φ⁻¹(0.9): the band is the 10–90 % one

// The split-conformal quantiles of n errors (Vovk et al. 2005; Lei et al.,
// JASA 113, 2018): the ⌊0.1·(n + 1)⌋-th and the ⌈0.9·(n + 1)⌉-th smallest.
// A new exchangeable error lies below the first, and above the second, with
// probability at most 0.1 each, so between them with probability at least
// 0.8 (and below 0.8 + 2/(n + 1): 86 % for 28 days). NaN below 9 errors,
// where the first rank is 0.
struct ConformalQuantiles {
  double q10 = kNaN, q90 = kNaN;
};
ConformalQuantiles QuantilesOf(std::vector<double> errors) {
  const std::size_t n = errors.size();
  const std::size_t low_rank = (n + 1) / 10, high_rank = std::min(n, (9 * (n + 1) + 9) / 10);
  if (low_rank < 1) return {};
  std::sort(errors.begin(), errors.end());
  return {errors[low_rank - 1], errors[high_rank - 1]};
}

// The reference days of `today`: of the days before it in the reference
// window that are not suspect, the `neighbours` nearest in ln expected
// energy (ties: the more recent); their errors ln pi and their regimes.
struct Reference {
  std::vector<double> errors;       // ln pi
  std::vector<double> log_e_model;  // ln expected energy (Wh)
};
Reference ReferenceOf(const std::vector<IndexDay>& before, const IndexDay& today,
                      const IndexBandOptions& options) {
  std::vector<const IndexDay*> days;
  for (const IndexDay& d : before) {
    if (d.day_start_s >= today.day_start_s - options.reference_days * kDayS && !d.suspect) {
      days.push_back(&d);
    }
  }
  const double log_e = std::log(today.e_model_wh);
  auto distance = [log_e](const IndexDay* d) { return std::fabs(std::log(d->e_model_wh) - log_e); };
  std::stable_sort(days.begin(), days.end(), [&distance](const IndexDay* a, const IndexDay* b) {
    const double da = distance(a), db = distance(b);
    return da < db || (da == db && a->day_start_s > b->day_start_s);
  });
  if (days.size() > static_cast<std::size_t>(options.neighbours)) {
    days.resize(static_cast<std::size_t>(options.neighbours));
  }
  Reference reference;
  for (const IndexDay* d : days) {
    reference.errors.push_back(std::log(d->pi));
    reference.log_e_model.push_back(std::log(d->e_model_wh));
  }
  return reference;
}

// The band of the day and its part in the CUSUM (s, run: the state before it).
void Follow(Reference reference, const IndexBandOptions& bands, const IndexCusumOptions& cusum,
            double* s, int* run, IndexDay* day) {
  day->low = day->high = kNaN;
  if (static_cast<int>(reference.errors.size()) < bands.min_reference_days) return;
  // The regime test (index_band.h): the day's ln expected energy no farther
  // beyond its reference days' conformal range than that range is wide.
  const ConformalQuantiles regime = QuantilesOf(std::move(reference.log_e_model));
  const double log_e = std::log(day->e_model_wh);
  const double width = regime.q90 - regime.q10;
  if (!(regime.q10 - width <= log_e && log_e <= regime.q90 + width)) {
    day->withheld = true;
    return;
  }
  const ConformalQuantiles q = QuantilesOf(std::move(reference.errors));
  if (std::isnan(q.q10)) return;
  const double q10 = q.q10, q90 = q.q90;
  day->low = day->pi * std::exp(-q90);
  day->high = day->pi * std::exp(-q10);
  const double sigma = (q90 - q10) / (2.0 * kZ90);
  if (!(sigma > 0.0)) return;  // a reference without spread: a band, no evidence
  day->banded = true;
  day->z = (std::log(day->pi) - 0.5 * (q10 + q90)) / sigma;
  *s = std::max(0.0, *s - day->z - cusum.k_sigma);
  *run = *s > 0.0 ? *run + 1 : 0;
  day->s = *s;
  day->run_days = *run;
  day->alarm = *s >= cusum.h_sigma && *run >= cusum.min_days;
}

}  // namespace

std::vector<IndexDay> FollowIndex(std::span<const DayPerformance> days, bool thermal,
                                  const IndexBandOptions& bands, const IndexCusumOptions& cusum) {
  std::vector<IndexDay> out;
  double s = 0.0;
  int run = 0;
  for (const DayPerformance& d : days) {
    IndexDay day;
    day.day_start_s = d.day_start_s;
    day.pi = thermal ? d.pi_th : d.pi_el;
    day.e_model_wh = thermal ? d.e_th_model_wh : d.e_el_model_wh;
    if (!(thermal ? d.scored_th : d.scored_el) || !(day.pi > 0.0) || !std::isfinite(day.pi) ||
        !(day.e_model_wh > 0.0)) {
      continue;
    }
    Follow(ReferenceOf(out, day, bands), bands, cusum, &s, &run, &day);
    out.push_back(day);
    if (!day.alarm) continue;
    // The alarm judges its excursion's days (this one back to the day after
    // S was last 0) a fault: they leave the reference of every later day.
    // While the excursion is open they stay in it (index_band.h).
    for (auto it = out.rbegin(); it != out.rend(); ++it) {
      if (it != out.rbegin() && it->banded && (it->run_days == 0 || it->alarm)) break;
      if (it->banded) it->suspect = true;
    }
    s = 0.0;
    run = 0;
  }
  return out;
}

std::int64_t ChangeOnsetS(std::span<const IndexDay> days) {
  auto newest = std::find_if(days.rbegin(), days.rend(), [](const IndexDay& d) { return d.alarm; });
  if (newest == days.rend()) return -1;
  // The maximum-likelihood change point (index_band.h), walking back from
  // the alarm: ties keep the later day.
  std::int64_t onset = newest->day_start_s;
  double best = 0.0, loss = 0.0;
  int count = 0;
  for (auto it = newest; it != days.rend(); ++it) {
    if (!it->banded) continue;
    loss -= it->z;
    ++count;
    const double statistic = loss > 0.0 ? loss * loss / count : 0.0;
    if (statistic > best) {
      best = statistic;
      onset = it->day_start_s;
    }
  }
  return onset;
}

void SetIndexBands(std::span<const DayPerformance> earlier, const IndexBandOptions& bands,
                   const IndexCusumOptions& cusum, DayPerformance* day) {
  std::vector<DayPerformance> days(earlier.begin(), earlier.end());
  days.push_back(*day);
  for (const bool thermal : {false, true}) {
    if (!(thermal ? day->scored_th : day->scored_el)) continue;
    const std::vector<IndexDay> followed = FollowIndex(days, thermal, bands, cusum);
    const bool found = !followed.empty() && followed.back().day_start_s == day->day_start_s;
    (thermal ? day->pi_th_low : day->pi_el_low) = found ? followed.back().low : kNaN;
    (thermal ? day->pi_th_high : day->pi_el_high) = found ? followed.back().high : kNaN;
  }
}

}  // namespace pvtwin
