#include <algorithm>
#include <cmath>

#include "core/common/calendar.h"
#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

bool SplitDays(const Series& data, const Plant& plant, const DiagnosisOptions& options,
               Split* split, std::string* error) {
  const std::int64_t offset_s = SolarDayOffsetS(plant);
  std::vector<std::int64_t> day_starts;
  for (std::int64_t t : data.time_s) {
    const std::int64_t d = SolarDayStartS(t, offset_s);
    if (day_starts.empty() || day_starts.back() != d) day_starts.push_back(d);
  }
  const int n_days = static_cast<int>(day_starts.size());
  if (n_days < 2) {
    *error = "the data span " + std::to_string(n_days) +
             " local solar day; the diagnosis needs at least one training and one held-out day";
    return false;
  }
  split->offset_s = offset_s;
  split->day_starts = day_starts;
  split->data_start_s = data.time_s.front();
  split->cleanings = DetectCleanings(data, plant);
  if (CrossFitted(options)) {
    // Every day held out in turn: each fold trains on the other days.
    split->folds = n_days;
    split->train_days = n_days - 1;
    split->heldout_days = n_days;
    split->train_series = data;
    split->heldout_series = data;
    split->fold_of_row.resize(data.size());
    std::size_t day = 0;
    for (std::size_t i = 0; i < data.size(); ++i) {
      const std::int64_t d = SolarDayStartS(data.time_s[i], offset_s);
      while (day_starts[day] != d) ++day;
      split->fold_of_row[i] = static_cast<int>(day);
    }
    return true;
  }
  int train_days = options.train_days;
  if (train_days == 0)
    train_days = std::clamp(static_cast<int>(std::lround(n_days * 2.0 / 3.0)), 1, n_days - 1);
  if (train_days >= n_days) {
    *error = "train_days = " + std::to_string(train_days) + ": the data span only " +
             std::to_string(n_days) + " local solar days, none would be left for held-out";
    return false;
  }
  const int heldout_days = options.heldout_days == 0
                               ? n_days - train_days
                               : std::min(options.heldout_days, n_days - train_days);
  const std::int64_t train_end_s = day_starts[static_cast<std::size_t>(train_days)];
  const std::int64_t heldout_end_s =
      day_starts[static_cast<std::size_t>(train_days + heldout_days - 1)] + kSecondsPerDay;
  split->train_days = train_days;
  split->heldout_days = heldout_days;
  split->train_series = data.Slice(0, data.RowAtOrAfter(train_end_s));
  split->heldout_series = data.Between(train_end_s, heldout_end_s);
  return true;
}

}  // namespace pvtwin::diagnosis_stages
