#include "core/data/resample.h"

#include <array>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdint>

namespace pvtwin {
namespace {

std::string FormatNumber(double x) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, result.ptr);
}

bool IsWholeSeconds(double s) { return std::isfinite(s) && s == std::floor(s); }

// Start of the bucket of width step_s that holds t (floor, also before 1970).
std::int64_t BucketStart(std::int64_t t, std::int64_t step_s) {
  std::int64_t k = t / step_s;
  if (t % step_s < 0) --k;
  return k * step_s;
}

}  // namespace

bool Resample(const Series& in, double step_s, Series* out, std::string* error,
              std::vector<int>* n_samples) {
  assert(out != nullptr && error != nullptr);
  if (!(in.step_s > 0.0) || !IsWholeSeconds(in.step_s)) {
    *error = "input step " + FormatNumber(in.step_s) + " s must be a positive whole number";
    return false;
  }
  if (!IsWholeSeconds(step_s) || step_s < in.step_s || std::fmod(step_s, in.step_s) != 0.0) {
    *error = "step " + FormatNumber(step_s) + " s must be a whole multiple of the input step " +
             FormatNumber(in.step_s) + " s";
    return false;
  }
  for (std::size_t i = 1; i < in.size(); ++i) {
    if (in.time_s[i] <= in.time_s[i - 1]) {
      *error = "input times must be strictly increasing (row " + std::to_string(i) + ")";
      return false;
    }
  }

  const auto bucket_s = static_cast<std::int64_t>(step_s);
  const double expected_rows = step_s / in.step_s;
  std::vector<Channel> channels;  // present in the input, without kValid
  for (std::size_t c = 0; c < kNumChannels; ++c) {
    const auto channel = static_cast<Channel>(c);
    if (channel != Channel::kValid && in.Has(channel)) channels.push_back(channel);
  }
  const bool has_valid = in.Has(Channel::kValid);
  std::vector<AirChannel> air;  // the air channels present, averaged alike
  for (std::size_t c = 0; c < kNumAirChannels; ++c) {
    if (in.Has(static_cast<AirChannel>(c))) air.push_back(static_cast<AirChannel>(c));
  }
  std::array<double, kNumAirChannels> air_sum{};
  std::array<int, kNumAirChannels> air_present{};

  Series result;
  result.step_s = step_s;
  for (const Channel c : channels)
    result[c].reserve(static_cast<std::size_t>(static_cast<double>(in.size()) / expected_rows) + 1);
  std::vector<double>& valid = result[Channel::kValid];
  std::vector<int> counts;

  std::vector<double> sum(kNumChannels, 0.0);
  std::vector<int> present(kNumChannels, 0);
  std::size_t begin = 0;
  while (begin < in.size()) {
    const std::int64_t start_s = BucketStart(in.time_s[begin], bucket_s);
    std::size_t end = begin;
    bool all_valid = true;
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(present.begin(), present.end(), 0);
    air_sum.fill(0.0);
    air_present.fill(0);
    for (; end < in.size() && in.time_s[end] < start_s + bucket_s; ++end) {
      if (has_valid && in[Channel::kValid][end] == 0.0) all_valid = false;
      for (const Channel c : channels) {
        const double x = in[c][end];
        if (!std::isnan(x)) {
          sum[static_cast<std::size_t>(c)] += x;
          ++present[static_cast<std::size_t>(c)];
        }
      }
      for (const AirChannel c : air) {
        const double x = in[c][end];
        if (!std::isnan(x)) {
          air_sum[static_cast<std::size_t>(c)] += x;
          ++air_present[static_cast<std::size_t>(c)];
        }
      }
    }
    const auto n_rows = static_cast<int>(end - begin);
    result.time_s.push_back(start_s);
    for (const Channel c : channels) {
      const auto k = static_cast<std::size_t>(c);
      result[c].push_back(present[k] > 0 ? sum[k] / present[k] : std::nan(""));
    }
    for (const AirChannel c : air) {
      const auto k = static_cast<std::size_t>(c);
      result[c].push_back(air_present[k] > 0 ? air_sum[k] / air_present[k] : std::nan(""));
    }
    valid.push_back(all_valid && 2.0 * n_rows >= expected_rows ? 1.0 : 0.0);
    counts.push_back(n_rows);
    begin = end;
  }

  *out = std::move(result);
  if (n_samples != nullptr) *n_samples = std::move(counts);
  return true;
}

}  // namespace pvtwin
