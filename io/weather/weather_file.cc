#include "io/weather/weather_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "core/data/physical_limits.h"
#include "io/files/csv.h"
#include "io/platform/local_time.h"
#include "io/platform/time_format.h"

namespace pvtwin {

namespace {

using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kKmPerHourToMS = 1.0 / 3.6;
// The longest step and span read: a provider's step is 15 or 60 min; a
// forecast with its past days spans weeks. Beyond, a file is refused rather
// than turned into millions of 1-min rows.
constexpr std::int64_t kMaxStepS = 3600;
constexpr std::int64_t kMaxSpanS = 100 * 86400;
constexpr std::int64_t kLatestTimeS = 4102444800;  // 2100-01-01

// "" when the stamps t (evenly spaced, checked) are within the limits.
std::string SpanProblem(const std::vector<std::int64_t>& t) {
  const std::int64_t step = t[1] - t[0];
  if (t.front() < 0 || t.back() > kLatestTimeS) return "expected times between 1970 and 2100";
  if (step > kMaxStepS) {
    return "a step of " + std::to_string(step) + " s: expected at most 3600 s (hourly)";
  }
  if (t.back() - t.front() > kMaxSpanS) {
    return "spans " + std::to_string((t.back() - t.front()) / 86400) +
           " days: expected at most 100 days";
  }
  return "";
}

// One Open-Meteo variable pvtwin reads: its name, the units it accepts with
// the factor to pvtwin's unit, and where it goes.
struct UnitFactor {
  const char* unit;
  double factor;
};
struct OpenMeteoVariable {
  const char* name;
  std::vector<UnitFactor> units;
  std::vector<double> ProviderWeather::*member;  // null: handled apart (direct_radiation)
};

const std::vector<OpenMeteoVariable>& Variables() {
  static const std::vector<UnitFactor> kWm2 = {{"W/m²", 1.0}, {"W/m2", 1.0}};
  static const std::vector<UnitFactor> kCelsius = {{"°C", 1.0}};
  static const std::vector<UnitFactor> kPercent = {{"%", 1.0}};
  static const std::vector<OpenMeteoVariable> kVariables = {
      {"global_tilted_irradiance", kWm2, &ProviderWeather::gti_w_m2},
      {"shortwave_radiation", kWm2, &ProviderWeather::ghi_w_m2},
      {"diffuse_radiation", kWm2, &ProviderWeather::dhi_w_m2},
      {"direct_radiation", kWm2, nullptr},
      {"direct_normal_irradiance", kWm2, &ProviderWeather::dni_w_m2},
      {"temperature_2m", kCelsius, &ProviderWeather::t_amb_c},
      {"dew_point_2m", kCelsius, &ProviderWeather::dew_point_c},
      {"relative_humidity_2m", kPercent, &ProviderWeather::relative_humidity_pct},
      {"cloud_cover", kPercent, &ProviderWeather::cloud_cover_pct},
      {"wind_speed_10m", {{"m/s", 1.0}, {"km/h", kKmPerHourToMS}}, &ProviderWeather::wind_m_s},
  };
  return kVariables;
}

// Physical limits per variable in pvtwin's unit (after conversion; the
// table: core/data/physical_limits.h): a value outside is read as missing
// with a note (as the CSV reader does).
PhysicalLimit LimitOf(const std::string& name) {
  if (name == "temperature_2m" || name == "dew_point_2m") {
    return ProviderLimitOf(ProviderQuantity::kAirTemperatureC);
  }
  if (name == "relative_humidity_2m" || name == "cloud_cover") {
    return ProviderLimitOf(ProviderQuantity::kPercent);
  }
  if (name == "wind_speed_10m") return ProviderLimitOf(ProviderQuantity::kWindAt10mMS);
  return ProviderLimitOf(ProviderQuantity::kIrradianceWM2);
}

class OpenMeteoReader {
 public:
  OpenMeteoReader(const std::string& name, WeatherFile* out, Diagnostics* errors)
      : name_(name), out_(out), errors_(errors) {}

  void Read(const json& root) {
    const char* block = root.contains("minutely_15") ? "minutely_15" : "hourly";
    block_ = block;
    if (!root.contains(block) || !root[block].is_object()) {
      Error("hourly",
            "missing: expected an object \"hourly\" or \"minutely_15\" with \"time\" "
            "and the weather variables");
      return;
    }
    const json& data = root[block];
    const std::string units_name = block_ + "_units";
    const json* units =
        root.contains(units_name) && root[units_name].is_object() ? &root[units_name] : nullptr;
    out_->format = "Open-Meteo JSON, " + block_;
    if (block_ == "minutely_15" && root.contains("hourly")) {
      out_->notes.push_back("hourly: ignored, minutely_15 is read (ask for one of them)");
    }
    out_->weather.irradiance_offset_s = 0.0;  // set with the step below
    if (!ReadTimes(root, data)) return;
    bool any = false;
    std::vector<double> direct_horizontal;
    for (const OpenMeteoVariable& v : Variables()) {
      if (!data.contains(v.name)) continue;
      std::vector<double> values;
      if (!ReadVariable(data, units, v, &values)) continue;
      any = true;
      if (v.member != nullptr) {
        out_->weather.*v.member = std::move(values);
      } else {
        direct_horizontal = std::move(values);
      }
    }
    DiffuseFromDirect(direct_horizontal);
    if (!any && errors_->empty()) {
      Error(block_,
            "no weather variable pvtwin reads: expected some of global_tilted_irradiance, "
            "shortwave_radiation, diffuse_radiation, direct_radiation, "
            "direct_normal_irradiance, temperature_2m, dew_point_2m, "
            "relative_humidity_2m, cloud_cover, wind_speed_10m");
    }
  }

 private:
  void Error(const std::string& field, const std::string& rule, const std::string& value = "") {
    errors_->push_back({name_, 0, field, value, rule});
  }
  std::string Field(const std::string& var) const { return block_ + "." + var; }
  std::string Field(const std::string& var, std::size_t i) const {
    return Field(var) + "[" + std::to_string(i) + "]";
  }

  // The zone of local ISO times: `timezone` when the tz database knows it,
  // else the fixed utc_offset_seconds.
  std::optional<NaiveTimeZone> Zone(const json& root) {
    std::string why;
    if (root.contains("timezone") && root["timezone"].is_string()) {
      if (auto zone = NaiveTimeZone::Parse(root["timezone"].get<std::string>(), &why)) return zone;
    }
    if (root.contains("utc_offset_seconds") && root["utc_offset_seconds"].is_number_integer()) {
      const long long offset = root["utc_offset_seconds"].get<long long>();
      char text[48];
      std::snprintf(text, sizeof text, "%c%02lld:%02lld", offset < 0 ? '-' : '+',
                    std::llabs(offset) / 3600, std::llabs(offset) % 3600 / 60);
      if (auto zone = NaiveTimeZone::Parse(text, &why)) return zone;
    }
    return std::nullopt;
  }

  bool ReadTimes(const json& root, const json& data) {
    if (!data.contains("time") || !data["time"].is_array()) {
      Error(Field("time"), "missing: expected an array of time stamps");
      return false;
    }
    const std::optional<NaiveTimeZone> zone = Zone(root);
    const json& times = data["time"];
    std::vector<std::int64_t>& t = out_->weather.time_s;
    for (std::size_t i = 0; i < times.size(); ++i) {
      std::int64_t unix_s = 0;
      std::string why;
      if (times[i].is_number_integer()) {
        unix_s = times[i].get<std::int64_t>();
      } else if (!times[i].is_string() ||
                 !ParseTimeIn(times[i].get<std::string>(), zone ? &*zone : nullptr,
                              t.empty() ? std::numeric_limits<std::int64_t>::min() : t.back(),
                              &unix_s, &why)) {
        Error(Field("time", i),
              "expected an ISO 8601 time or unix seconds" + (why.empty() ? "" : " (" + why + ")"),
              times[i].dump());
        return false;
      }
      if (unix_s < 0 || unix_s > kLatestTimeS) {
        Error(Field("time", i), "expected a time between 1970 and 2100", times[i].dump());
        return false;
      }
      if (!t.empty() && unix_s <= t.back()) {
        Error(Field("time", i), "must be later than " + Field("time", i - 1), times[i].dump());
        return false;
      }
      t.push_back(unix_s);
    }
    return CheckStep();
  }

  bool CheckStep() {
    const std::vector<std::int64_t>& t = out_->weather.time_s;
    if (t.size() < 2) {
      Error(Field("time"), "expected at least 2 time stamps to tell the step");
      return false;
    }
    const std::int64_t step = t[1] - t[0];
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] % 60 != 0 || (i > 0 && t[i] - t[i - 1] != step) || step % 60 != 0) {
        Error(Field("time", i),
              "time stamps must be whole minutes, evenly spaced (step " + std::to_string(step) +
                  " s from the first two)",
              FormatIsoUtc(t[i]));
        return false;
      }
    }
    if (const std::string problem = SpanProblem(t); !problem.empty()) {
      Error(Field("time"), problem);
      return false;
    }
    out_->weather.step_s = static_cast<double>(step);
    out_->weather.irradiance_offset_s = -static_cast<double>(step);  // the preceding interval
    out_->weather.instant_offset_s = 0.0;
    return true;
  }

  bool ReadVariable(const json& data, const json* units, const OpenMeteoVariable& v,
                    std::vector<double>* values) {
    const json& array = data[v.name];
    const std::size_t n = out_->weather.time_s.size();
    if (!array.is_array()) {
      Error(Field(v.name), "expected an array of numbers", array.dump().substr(0, 40));
      return false;
    }
    if (array.size() != n) {
      Error(Field(v.name), std::to_string(array.size()) + " values, but " + Field("time") +
                               " has " + std::to_string(n) +
                               ": arrays must have one value per "
                               "time stamp");
      return false;
    }
    std::optional<double> factor = UnitFactorOf(units, v);
    if (!factor) return false;
    const PhysicalLimit limit = LimitOf(v.name);
    std::size_t nulls = 0, outside = 0;
    values->assign(n, kNaN);
    for (std::size_t i = 0; i < n; ++i) {
      if (array[i].is_null()) {
        ++nulls;
        continue;
      }
      if (!array[i].is_number()) {
        Error(Field(v.name, i), "expected a number or null", array[i].dump().substr(0, 40));
        return false;
      }
      const double x = array[i].get<double>() * *factor;
      if (!limit.Contains(x)) {
        ++outside;
        continue;
      }
      (*values)[i] = x;
    }
    if (nulls > 0) {
      out_->missing_values += nulls;
      out_->notes.push_back(Field(v.name) + ": " + std::to_string(nulls) +
                            " null values, read as missing (not as zero)");
    }
    if (outside > 0) {
      out_->missing_values += outside;
      out_->notes.push_back(Field(v.name) + ": " + std::to_string(outside) +
                            " values outside the physical limits, read as missing");
    }
    return true;
  }

  std::optional<double> UnitFactorOf(const json* units, const OpenMeteoVariable& v) {
    const std::string field = block_ + "_units." + v.name;
    std::string expected;
    for (const UnitFactor& u : v.units)
      expected += (expected.empty() ? "\"" : " or \"") + std::string(u.unit) + "\"";
    if (units == nullptr || !units->contains(v.name) || !(*units)[v.name].is_string()) {
      Error(field,
            "missing: the unit of " + Field(v.name) + " is needed (expected " + expected + ")");
      return std::nullopt;
    }
    const std::string unit = (*units)[v.name].get<std::string>();
    for (const UnitFactor& u : v.units) {
      if (unit == u.unit) return u.factor;
    }
    Error(field, "unknown unit: expected " + expected, "\"" + unit + "\"");
    return std::nullopt;
  }

  // DHI = GHI − direct horizontal when the file gives direct_radiation and
  // no diffuse_radiation.
  void DiffuseFromDirect(const std::vector<double>& direct) {
    ProviderWeather& w = out_->weather;
    if (direct.empty() || !w.dhi_w_m2.empty() || w.ghi_w_m2.empty()) return;
    w.dhi_w_m2.assign(w.ghi_w_m2.size(), kNaN);
    for (std::size_t i = 0; i < direct.size(); ++i) {
      w.dhi_w_m2[i] = std::clamp(w.ghi_w_m2[i] - direct[i], 0.0, std::max(0.0, w.ghi_w_m2[i]));
      if (std::isnan(w.ghi_w_m2[i]) || std::isnan(direct[i])) w.dhi_w_m2[i] = kNaN;
    }
  }

  std::string name_;
  std::string block_;
  WeatherFile* out_;
  Diagnostics* errors_;
};

bool ParseJson(const std::string& text, const std::string& name, WeatherFile* out,
               Diagnostics* errors) {
  json root = json::parse(text, nullptr, false);
  if (root.is_discarded()) {
    // Parse again with exceptions off is not possible; the SAX error is
    // located by a second pass that records the byte offset.
    struct Locator : nlohmann::json_sax<json> {
      std::size_t at = 0;
      std::string what;
      bool null() override { return true; }
      bool boolean(bool) override { return true; }
      bool number_integer(number_integer_t) override { return true; }
      bool number_unsigned(number_unsigned_t) override { return true; }
      bool number_float(number_float_t, const string_t&) override { return true; }
      bool string(string_t&) override { return true; }
      bool binary(binary_t&) override { return true; }
      bool start_object(std::size_t) override { return true; }
      bool key(string_t&) override { return true; }
      bool end_object() override { return true; }
      bool start_array(std::size_t) override { return true; }
      bool end_array() override { return true; }
      bool parse_error(std::size_t position, const std::string&,
                       const nlohmann::detail::exception& e) override {
        at = position;
        what = e.what();
        return false;
      }
    } locator;
    json::sax_parse(text, &locator);
    const bool truncated = locator.at >= text.size();
    errors->push_back({name, 0, "", "",
                       truncated ? "truncated JSON: the text ends inside a value (after " +
                                       std::to_string(text.size()) + " bytes)"
                                 : "not valid JSON at byte " + std::to_string(locator.at) + " of " +
                                       std::to_string(text.size())});
    return false;
  }
  if (!root.is_object()) {
    errors->push_back({name, 0, "", "", "expected a JSON object as Open-Meteo sends it"});
    return false;
  }
  const std::size_t before = errors->size();
  OpenMeteoReader(name, out, errors).Read(root);
  return errors->size() == before;
}

// The canonical CSV: each row the mean of [time, time + step).
bool ParseCsv(const std::string& text, const std::string& name, WeatherFile* out,
              Diagnostics* errors) {
  std::istringstream in(text);
  CsvReadOptions options;
  options.weather_only = true;
  Series s;
  Diagnostics warnings;
  if (!ParseCanonicalCsv(in, name, options, &s, errors, &warnings)) return false;
  for (const Diagnostic& w : warnings) out->notes.push_back(w.ToString());
  if (s.size() < 2) {
    errors->push_back({name, 0, "time", "", "expected at least 2 rows to tell the step"});
    return false;
  }
  const std::int64_t step = s.time_s[1] - s.time_s[0];
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.time_s[i] % 60 != 0 || step % 60 != 0 ||
        (i > 0 && s.time_s[i] - s.time_s[i - 1] != step)) {
      errors->push_back({name, static_cast<int>(i) + 2, "time", FormatIsoUtc(s.time_s[i]),
                         "time stamps must be whole minutes, evenly spaced (step " +
                             std::to_string(step) + " s from the first two rows)"});
      return false;
    }
  }
  if (const std::string problem = SpanProblem(s.time_s); !problem.empty()) {
    errors->push_back({name, 0, "time", "", problem});
    return false;
  }
  ProviderWeather& w = out->weather;
  w.time_s = s.time_s;
  w.step_s = static_cast<double>(step);
  w.irradiance_offset_s = 0.0;
  w.instant_offset_s = 0.5 * w.step_s;
  const std::pair<Channel, std::vector<double> ProviderWeather::*> kMap[] = {
      {Channel::kGPoaWM2, &ProviderWeather::gti_w_m2},
      {Channel::kGhiWM2, &ProviderWeather::ghi_w_m2},
      {Channel::kDhiWM2, &ProviderWeather::dhi_w_m2},
      {Channel::kTAmbC, &ProviderWeather::t_amb_c},
      {Channel::kWindMS, &ProviderWeather::wind_m_s},
      {Channel::kTSkyC, &ProviderWeather::t_sky_c},
      {Channel::kLwDownWM2, &ProviderWeather::lw_down_w_m2}};
  for (const auto& [channel, member] : kMap) {
    if (!s.Has(channel)) continue;
    w.*member = s[channel];
    const auto missing = static_cast<std::size_t>(std::count_if(
        s[channel].begin(), s[channel].end(), [](double v) { return std::isnan(v); }));
    if (missing > 0) {
      out->missing_values += missing;
      out->notes.push_back(name + ": " + std::string(ChannelName(channel)) + ": " +
                           std::to_string(missing) + " empty cells, read as missing");
    }
  }
  out->format = "canonical CSV";
  return true;
}

}  // namespace

bool ParseWeatherFile(const std::string& text, const std::string& name, WeatherFile* out,
                      Diagnostics* errors) {
  *out = WeatherFile{};
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) {
    errors->push_back({name, 0, "", "", "empty file: expected Open-Meteo JSON or a canonical CSV"});
    return false;
  }
  return text[first] == '{' ? ParseJson(text, name, out, errors)
                            : ParseCsv(text, name, out, errors);
}

bool ReadWeatherFile(const std::string& path, WeatherFile* out, Diagnostics* errors) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    errors->push_back({path, 0, "", "", "cannot open the file"});
    return false;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return ParseWeatherFile(text.str(), path, out, errors);
}

}  // namespace pvtwin
