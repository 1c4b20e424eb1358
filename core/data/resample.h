// Averaging a series onto a coarser, aligned time grid (5 s samples → 1 min
// measurements, doc/contracts.md "sample_5s → measurement_1min").
#pragma once

#include <string>
#include <vector>

#include "core/common/series.h"

namespace pvtwin {

// Averages the rows of `in` into buckets [k·step_s, (k+1)·step_s) of unix
// time; a bucket's time is its start (the canonical time convention).
//   * Each present channel's value is the mean of the bucket's non-NaN
//     values, NaN if there are none.
//   * A bucket is emitted only if at least one input row falls in it: gaps in
//     the input stay gaps.
//   * `valid` (always in the output) is 1 only if every contributing row is
//     valid (a row without a `valid` value counts as valid) and the bucket
//     holds at least half of the step_s / in.step_s rows it should have;
//     otherwise 0. A half-empty minute is still averaged, but kept out of the
//     objective and the errors.
//   * out->step_s = step_s.
// step_s must be a whole number of seconds, and a multiple of in.step_s
// (which must be > 0, and is itself whole seconds). in.time_s must be
// strictly increasing. Otherwise returns false, sets *error and leaves *out
// untouched. Runs in one pass, linear in the number of rows.
// n_samples, if not null, receives the number of input rows of each bucket.
// Apply ApplyPaperCorrections (core/data/qc.h) before averaging, as the paper
// corrects the raw values.
bool Resample(const Series& in, double step_s, Series* out, std::string* error,
              std::vector<int>* n_samples = nullptr);

}  // namespace pvtwin
