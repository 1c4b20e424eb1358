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
  const std::int64_t data_start_s = data.time_s.front();
  const Series train_series = data.Slice(0, data.RowAtOrAfter(train_end_s));
  const Series heldout_series = data.Between(train_end_s, heldout_end_s);
  split->offset_s = offset_s;
  split->day_starts = day_starts;
  split->train_days = train_days;
  split->heldout_days = heldout_days;
  split->data_start_s = data_start_s;
  split->train_series = train_series;
  split->heldout_series = heldout_series;
  split->cleanings = DetectCleanings(data, plant);
  return true;
}

}  // namespace pvtwin::diagnosis_stages
