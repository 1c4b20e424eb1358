#include "daemon/service/window_data.h"

#include <cmath>

namespace pvtwin::cli {

const char* WindowData::Table() const {
  switch (source) {
    case WindowSource::kMinutes:
      return "measurement_1min";
    case WindowSource::kIntervals:
      return "measurement_interval";
    case WindowSource::kNone:
      break;
  }
  return "";
}

std::string WindowData::Describe() const {
  if (source != WindowSource::kIntervals) return "1-min rows";
  return std::to_string(static_cast<long long>(std::llround(rows.step_s / 60.0))) +
         "-min rows of measurement_interval";
}

bool ReadWindowData(Store& store, std::int64_t from_ts, std::int64_t to_ts, WindowData* out,
                    std::string* error) {
  WindowData data;
  if (!store.ReadMinutes(from_ts, to_ts, &data.rows, error)) return false;
  if (data.rows.size() > 0) {
    data.source = WindowSource::kMinutes;
  } else {
    if (!store.ReadIntervalRows(from_ts, to_ts, &data.rows, error)) return false;
    if (data.rows.size() > 0) data.source = WindowSource::kIntervals;
  }
  *out = std::move(data);
  return true;
}

double StepForData(double step_s, double data_step_s) {
  if (!(step_s > 0.0) || !(data_step_s > 0.0)) return data_step_s;
  const double ratio = step_s / data_step_s;
  return ratio >= 1.0 && ratio == std::floor(ratio) ? step_s : data_step_s;
}

}  // namespace pvtwin::cli
