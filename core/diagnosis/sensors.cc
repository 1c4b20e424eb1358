#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "core/diagnosis/stages.h"
#include "core/model/thermal_model.h"
#include "core/monitor/monitoring.h"

namespace pvtwin::diagnosis_stages {

namespace {

// Sky temperature minus air temperature of row i, NaN without a sky channel.
double SkyExcessK(const Series& s, std::size_t i) {
  return MeasuredSkyTemperatureC(s, i) - s.At(Channel::kTAmbC, i);
}

}  // namespace

std::vector<SensorFinding> CheckSensors(const Series& data, const Plant& plant) {
  std::map<std::pair<std::string, std::string>, std::vector<SensorFault>> by_kind;
  for (SensorFault& f : FindSensorFaults(data, plant)) {
    by_kind[{f.channel, f.kind}].push_back(std::move(f));
  }
  std::vector<SensorFinding> out;
  for (const auto& [key, faults] : by_kind) {
    SensorFinding s;
    s.channel = key.first;
    s.kind = key.second;
    std::vector<double> excess;
    for (const SensorFault& f : faults) {
      for (std::size_t i = data.RowAtOrAfter(f.start_s); i < data.RowAtOrAfter(f.end_s); ++i) {
        ++s.rows;
        if (s.kind == "sky_warmer_than_air") excess.push_back(SkyExcessK(data, i));
      }
    }
    s.share =
        data.size() > 0 ? static_cast<double>(s.rows) / static_cast<double>(data.size()) : 0.0;
    std::erase_if(excess, [](double e) { return !std::isfinite(e); });
    if (!excess.empty()) {
      std::nth_element(excess.begin(), excess.begin() + excess.size() / 2, excess.end());
      s.size = excess[excess.size() / 2];
    }
    s.detail =
        faults.front().detail +
        (faults.size() > 1 ? " (first of " + std::to_string(faults.size()) + " intervals)" : "");
    out.push_back(std::move(s));
  }
  std::sort(out.begin(), out.end(),
            [](const SensorFinding& a, const SensorFinding& b) { return a.rows > b.rows; });
  return out;
}

}  // namespace pvtwin::diagnosis_stages

namespace pvtwin {

std::string SensorSizeText(const SensorFinding& f) {
  if (f.size_unit.empty()) return "× " + FixedDecimals(f.size, 3);
  return FixedDecimals(f.size, 1) + " " + f.size_unit;
}

std::vector<SensorFault> DiagnosedSensorFaults(const DiagnosisResult& result, std::int64_t end_s) {
  std::vector<SensorFault> out;
  for (const SensorFinding& f : result.sensors) {
    if (f.from_s <= 0 || f.from_s >= end_s) continue;
    out.push_back({f.channel, f.from_s, end_s, f.kind, f.detail});
  }
  return out;
}

}  // namespace pvtwin
