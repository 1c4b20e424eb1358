#include "config/plant_config.h"

#include <sys/stat.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "config/libpq_api.h"
#include "config/toml_reader.h"
#include "core/common/units.h"
#include "core/model/variant.h"

namespace pvtwin {
namespace {

using namespace config_detail;

// [plant]: one row per number key. Angles are converted to radians.
struct PlantKey {
  std::string_view key;
  bool required;
  Interval range;
  double Plant::*member;
  bool degrees;
};

constexpr PlantKey kPlantKeys[] = {
    {"latitude_deg", kRequired, Closed(-90, 90), &Plant::latitude_rad, true},
    {"longitude_deg", kRequired, Closed(-180, 180), &Plant::longitude_rad, true},
    {"elevation_m", kOptional, Closed(-500, 9000), &Plant::elevation_m, false},
    {"tilt_deg", kRequired, Closed(0, 90), &Plant::tilt_rad, true},
    {"azimuth_deg", kRequired, HalfOpen(0, 360), &Plant::azimuth_rad, true},
    {"area_m2", kRequired, LeftOpen(0, 1e6), &Plant::area_m2, false},
    {"fluid_cp_j_kgk", kOptional, Closed(1000, 5000), &Plant::fluid_cp_j_kgk, false},
    {"fluid_density_kg_m3", kOptional, Closed(500, 2000), &Plant::fluid_density_kg_m3, false},
    {"ground_albedo", kOptional, Closed(0, 1), &Plant::ground_albedo, false},
    {"iam_b0", kOptional, HalfOpen(0, 1), &Plant::iam_b0, false},
    {"pv_t_ref_c", kOptional, Closed(-50, 100), &Plant::pv_t_ref_c, false},
    {"pv_g_ref_w_m2", kOptional, Closed(100, 1500), &Plant::pv_g_ref_w_m2, false},
    {"pv_temp_coeff_per_k", kOptional, Closed(-0.02, 0.01), &Plant::pv_temp_coeff_per_k, false},
    {"pv_irr_coeff_m2_w", kOptional, Closed(-1e-3, 1e-3), &Plant::pv_irr_coeff_m2_w, false},
    {"collector_height_m", kOptional, Closed(0.5, 200), &Plant::collector_height_m, false},
};

void ReadPlant(SectionReader& r, Plant* plant) {
  for (const PlantKey& k : kPlantKeys) {
    double value = 0.0;
    if (r.Number(k.key, k.required, k.range, &value)) {
      plant->*k.member = k.degrees ? DegToRad(value) : value;
    }
  }
  // Where the sky temperature comes from (core/model/thermal_model.h,
  // SkyTemperaturesC).
  std::string sky;
  if (r.Choice("sky", kOptional, {"auto", "measured", "estimated"}, &sky)) {
    plant->sky = sky == "measured"    ? SkySource::kMeasured
                 : sky == "estimated" ? SkySource::kEstimated
                                      : SkySource::kAuto;
  }
}

}  // namespace

std::vector<std::pair<std::string, double>> PlantKeyValues(const Plant& plant) {
  std::vector<std::pair<std::string, double>> values;
  for (const PlantKey& k : kPlantKeys) {
    values.emplace_back(std::string(k.key),
                        k.degrees ? RadToDeg(plant.*k.member) : plant.*k.member);
  }
  // [plant] sky as a code: 0 auto, 1 measured, 2 estimated.
  values.emplace_back("sky", static_cast<double>(plant.sky));
  return values;
}

bool PlantFromKeyValues(const std::vector<std::pair<std::string, double>>& values, Plant* plant,
                        std::string* error) {
  Plant result;
  for (const PlantKey& k : kPlantKeys) {
    const auto it = std::find_if(values.begin(), values.end(),
                                 [&](const auto& kv) { return kv.first == k.key; });
    if (it == values.end()) {
      if (!k.required) continue;
      *error = std::string(k.key) + ": missing";
      return false;
    }
    if (!k.range.Contains(it->second)) {
      *error = std::string(k.key) + " = " + FormatNumber(it->second) + ": out of range";
      return false;
    }
    result.*k.member = k.degrees ? DegToRad(it->second) : it->second;
  }
  for (const auto& [key, value] : values) {
    if (key != "sky") continue;
    if (value != 0.0 && value != 1.0 && value != 2.0) {
      *error = "sky = " + FormatNumber(value) + ": expected 0 (auto), 1 (measured) or 2 (estimated)";
      return false;
    }
    result.sky = static_cast<SkySource>(static_cast<int>(value));
  }
  *plant = result;
  return true;
}

std::string PlantMismatch(const Plant& configured,
                          const std::vector<std::pair<std::string, double>>& stored) {
  if (stored.empty()) return "";
  Plant recorded;
  std::string error;
  if (!PlantFromKeyValues(stored, &recorded, &error)) {
    return "the store's plant_config cannot be read (" + error + ")";
  }
  // Great-circle distance (haversine) on a sphere of the Earth's mean radius.
  constexpr double kEarthRadiusM = 6371000.0;
  const double dlat = configured.latitude_rad - recorded.latitude_rad;
  const double dlon = configured.longitude_rad - recorded.longitude_rad;
  const double h = std::sin(dlat / 2) * std::sin(dlat / 2) +
                   std::cos(configured.latitude_rad) * std::cos(recorded.latitude_rad) *
                       std::sin(dlon / 2) * std::sin(dlon / 2);
  const double distance_m = 2.0 * kEarthRadiusM * std::asin(std::min(1.0, std::sqrt(h)));
  std::string differs;
  auto degrees = [](double rad) { return FormatNumber(RadToDeg(rad)); };
  if (distance_m > kSameSiteM) {
    differs += "the site: the config's latitude_deg = " + degrees(configured.latitude_rad) +
               ", longitude_deg = " + degrees(configured.longitude_rad) + ", the store's " +
               degrees(recorded.latitude_rad) + ", " + degrees(recorded.longitude_rad) + " (" +
               FormatNumber(std::round(distance_m / 100.0) / 10.0) + " km apart)";
  }
  if (std::fabs(configured.area_m2 - recorded.area_m2) > kSameAreaShare * recorded.area_m2) {
    differs += std::string(differs.empty() ? "" : "; ") + "the area: the config's area_m2 = " +
               FormatNumber(configured.area_m2) + ", the store's " +
               FormatNumber(recorded.area_m2);
  }
  return differs;
}

namespace {

struct UrlPlaceholder {
  std::string_view name;
  double (*value)(const Plant&);
};
constexpr UrlPlaceholder kUrlPlaceholders[] = {
    {"lat", [](const Plant& p) { return RadToDeg(p.latitude_rad); }},
    {"lon", [](const Plant& p) { return RadToDeg(p.longitude_rad); }},
    {"tilt", [](const Plant& p) { return RadToDeg(p.tilt_rad); }},
    {"azimuth", [](const Plant& p) { return RadToDeg(p.azimuth_rad); }},
    {"om_azimuth", [](const Plant& p) { return RadToDeg(p.azimuth_rad) - 180.0; }},
    {"elevation", [](const Plant& p) { return p.elevation_m; }},
};

// Calls on_text / on_placeholder for the pieces of url; false with *error
// at an unknown or unclosed placeholder.
template <class OnText, class OnPlaceholder>
bool WalkUrlTemplate(const std::string& url, OnText on_text, OnPlaceholder on_placeholder,
                     std::string* error) {
  std::size_t at = 0;
  while (at < url.size()) {
    const std::size_t open = url.find('{', at);
    on_text(url.substr(at, open == std::string::npos ? std::string::npos : open - at));
    if (open == std::string::npos) break;
    const std::size_t close = url.find('}', open);
    if (close == std::string::npos) {
      *error = "unclosed '{' at character " + std::to_string(open + 1);
      return false;
    }
    const std::string_view name(url.data() + open + 1, close - open - 1);
    const auto it = std::find_if(std::begin(kUrlPlaceholders), std::end(kUrlPlaceholders),
                                 [&](const UrlPlaceholder& p) { return p.name == name; });
    if (it == std::end(kUrlPlaceholders)) {
      *error = "unknown placeholder {" + std::string(name) +
               "} (known: {lat}, {lon}, {tilt}, {azimuth}, {om_azimuth}, {elevation})";
      return false;
    }
    on_placeholder(*it);
    at = close + 1;
  }
  return true;
}

}  // namespace

bool CheckWeatherUrlTemplate(const std::string& url, std::string* error) {
  if (!url.starts_with("http://") && !url.starts_with("https://")) {
    *error = "expected an http:// or https:// URL";
    return false;
  }
  return WalkUrlTemplate(
      url, [](const std::string&) {}, [](const UrlPlaceholder&) {}, error);
}

std::string ExpandWeatherUrl(const std::string& url, const Plant& plant) {
  std::string out, error;
  WalkUrlTemplate(
      url, [&](const std::string& text) { out += text; },
      [&](const UrlPlaceholder& p) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.4f", p.value(plant));
        std::string number = buf;
        while (number.back() == '0') number.pop_back();
        if (number.back() == '.') number.pop_back();
        out += number;
      },
      &error);
  return out;
}

namespace {

void ReadStorage(SectionReader& r, StorageConfig* storage) {
  r.String("path", kOptional, &storage->path);
  r.Integer("raw_retention_days", kOptional, Closed(1, 3650), &storage->raw_retention_days);
}

void ReadPoll(SectionReader& r, PollConfig* poll) {
  // The 1-min aggregation counts whole periods per minute (core/aggregate.h).
  double period_s = poll->period_s;
  if (r.Number("period_s", kOptional, Closed(1, 60), &period_s)) {
    if (period_s != std::floor(period_s) || std::fmod(60.0, period_s) != 0.0) {
      r.Reject("period_s", "must be a whole number of seconds that divides 60");
    } else {
      poll->period_s = period_s;
    }
  }
}

void ReadCalibration(SectionReader& r, CalibrationConfig* calibration) {
  // The variant grammar (paper Table 6 names plus "+effect") belongs to the
  // model layer; it is checked here so that every command reports it at its
  // line.
  std::string variant;
  if (r.String("variant", kOptional, &variant)) {
    ModelSpec spec;
    std::string why;
    if (ParseVariant(variant, &spec, &why)) {
      calibration->variant = variant;
    } else {
      r.Reject("variant", why);
    }
  }
  r.Integer("window_days", kOptional, Closed(1, 60), &calibration->window_days);
  r.Boolean("refit_full_window", kOptional, &calibration->refit_full_window);
  double step_s = calibration->step_s;
  if (r.Number("step_s", kOptional, Closed(5, 900), &step_s)) {
    if (step_s != std::floor(step_s) || std::fmod(86400.0, step_s) != 0.0) {
      r.Reject("step_s", "must be a whole number of seconds that divides 86400");
    } else {
      calibration->step_s = step_s;
    }
  }
  constexpr std::string_view kClockRule = "expected a local time \"HH:MM\" (00:00 to 23:59)";
  std::string at;
  if (r.String("at", kOptional, &at, kClockRule)) {
    if (int h = 0, m = 0; ParseClockTime(at, &h, &m)) {
      calibration->at = at;
    } else {
      r.Reject("at", kClockRule);
    }
  }
  constexpr std::string_view kZoneRule =
      "expected a zone of the tz database, e.g. \"Europe/Vienna\"";
  std::string zone;
  if (r.String("timezone", kOptional, &zone, kZoneRule)) {
    if (TimeZoneExists(zone)) {
      calibration->timezone = zone;
    } else {
      r.Reject("timezone", kZoneRule);
    }
  }
}

void ReadForecast(SectionReader& r, ForecastConfig* forecast) {
  r.Number("horizon_h", kOptional, LeftOpen(0, 168), &forecast->horizon_h);
  r.Number("refresh_min", kOptional, Closed(1, 1440), &forecast->refresh_min);
  constexpr std::string_view kUrlRule =
      "expected an http:// or https:// URL; placeholders {lat}, {lon}, {tilt}, {azimuth}, "
      "{om_azimuth}, {elevation}";
  std::string url;
  if (r.String("weather_url", kOptional, &url, kUrlRule)) {
    std::string why;
    if (!url.empty() && !CheckWeatherUrlTemplate(url, &why)) {
      r.Reject("weather_url", why);
    } else {
      forecast->weather_url = url;
    }
  }
  r.Number("weather_refresh_min", kOptional, Closed(5, 1440), &forecast->weather_refresh_min);
  r.Number("weather_timeout_s", kOptional, Closed(1, 600), &forecast->weather_timeout_s);
}

void ReadDiagnosis(SectionReader& r, DiagnosisConfig* d) {
  r.Boolean("enabled", kOptional, &d->enabled);
  r.Integer("every_days", kOptional, Closed(1, 365), &d->every_days);
  r.Number("timeout_s", kOptional, Closed(1, 86400), &d->timeout_s);
  r.Integer("keep", kOptional, Closed(1, 1000), &d->keep);
}

void ReadLog(SectionReader& r, LogConfig* log) {
  r.Integer("status_min", kOptional, Closed(0, 1440), &log->status_min);
}

void ReadMonitor(SectionReader& r, MonitorConfig* m) {
  r.Integer("drift_days", kOptional, Closed(2, 365), &m->drift_days);
  r.Integer("alarm_days", kOptional, Closed(1, 60), &m->alarm_days);
  r.Number("datasheet_eta0", kOptional, Closed(0, 1), &m->datasheet_eta0);
  r.Number("datasheet_c1_w_m2k", kOptional, Closed(0, 100), &m->datasheet_c1_w_m2k);
  r.Number("datasheet_c2_w_m2k2", kOptional, Closed(0, 1), &m->datasheet_c2_w_m2k2);
  r.Number("datasheet_c3_j_m3k", kOptional, Closed(0, 100), &m->datasheet_c3_j_m3k);
  r.Number("datasheet_c4", kOptional, Closed(0, 1), &m->datasheet_c4);
  r.Number("datasheet_c5_j_m2k", kOptional, Closed(0, 1e6), &m->datasheet_c5_j_m2k);
  r.Number("datasheet_c6_s_m", kOptional, Closed(0, 1), &m->datasheet_c6_s_m);
  r.Number("datasheet_kd", kOptional, Closed(0, 1.5), &m->datasheet_kd);
  r.Number("power_check_safety_factor", kOptional, LeftOpen(0, 1), &m->power_check_safety_factor);
}

void ReadSim(SectionReader& r, SimConfig* sim) {
  r.Choice("operation", kOptional, {"irradiance", "differential", "heat_pump"}, &sim->operation);
  const bool on = r.Number("pump_dt_on_k", kOptional, LeftOpen(0, 30), &sim->pump_dt_on_k);
  const bool off = r.Number("pump_dt_off_k", kOptional, Closed(0, 30), &sim->pump_dt_off_k);
  if ((on || off) && !(sim->pump_dt_off_k < sim->pump_dt_on_k)) {
    r.Reject(off ? "pump_dt_off_k" : "pump_dt_on_k",
             "pump_dt_off_k (" + FormatNumber(sim->pump_dt_off_k) +
                 ") must be below pump_dt_on_k (" + FormatNumber(sim->pump_dt_on_k) + ")");
  }
  r.Number("brine_below_ambient_k", kOptional, Closed(0, 30), &sim->brine_below_ambient_k);
  const bool lo = r.Number("brine_min_c", kOptional, Closed(-20, 30), &sim->brine_min_c);
  const bool hi = r.Number("brine_max_c", kOptional, Closed(-20, 30), &sim->brine_max_c);
  if ((lo || hi) && !(sim->brine_min_c <= sim->brine_max_c)) {
    r.Reject(hi ? "brine_max_c" : "brine_min_c", "brine_min_c (" + FormatNumber(sim->brine_min_c) +
                                                     ") must not exceed brine_max_c (" +
                                                     FormatNumber(sim->brine_max_c) + ")");
  }
}

// plant_id: what the fleet's dashboards show and the central key, so plain
// characters only.
bool IsPlantId(std::string_view id) {
  return id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
           return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                  c == '_' || c == '-' || c == '.';
         });
}

// url: parsed by libpq itself (URI or key=value), so the check sees what the
// connection will see; a password in it is refused without echoing it.
void CheckUploadUrl(SectionReader& r, const std::string& url) {
  try {
    Libpq();
  } catch (const std::runtime_error& e) {
    r.RejectHidden("url", std::string("cannot be checked, and the upload cannot run: ") + e.what());
    return;
  }
  char* why = nullptr;
  PQconninfoOption* options = Libpq().PQconninfoParse(url.c_str(), &why);
  if (options == nullptr) {
    std::string rule = "not a libpq connection string (postgresql://... or key=value)";
    if (why != nullptr) {
      std::string detail = why;
      while (!detail.empty() && detail.back() == '\n') detail.pop_back();
      rule += ": " + detail;
      Libpq().PQfreemem(why);
    }
    r.RejectHidden("url", rule);
    return;
  }
  for (const PQconninfoOption* o = options; o->keyword != nullptr; ++o) {
    if (std::string_view(o->keyword) == "password" && o->val != nullptr && *o->val != '\0') {
      r.RejectHidden("url",
                     "holds a password; the config is readable by the pvtwin group: put the "
                     "password in password_file, the systemd credential pgpassword, or ~/.pgpass");
    }
  }
  Libpq().PQconninfoFree(options);
}

void ReadUpload(SectionReader& r, UploadConfig* upload) {
  upload->enabled = true;
  if (r.String("url", kRequired, &upload->url)) CheckUploadUrl(r, upload->url);
  r.String("password_file", kOptional, &upload->password_file);
  if (r.String("plant_id", kRequired, &upload->plant_id) && !IsPlantId(upload->plant_id)) {
    r.Reject("plant_id", "expected up to 64 letters, digits, '_', '-' or '.'");
  }
  r.Number("interval_s", kOptional, Closed(1, 86400), &upload->interval_s);
  r.Integer("batch_rows", kOptional, Closed(1, 100000), &upload->batch_rows);
  r.Integer("forecast_days", kOptional, Closed(1, 3650), &upload->forecast_days);
}

void ReadDocument(const toml::table& root, const SourceText& source, const std::string& file,
                  Config* config, Diagnostics* errors) {
  using SectionFn = void (*)(SectionReader&, Config*);
  struct Section {
    std::string_view name;
    SectionFn read;
  };
  static constexpr Section kSections[] = {
      {"plant", [](SectionReader& r, Config* c) { ReadPlant(r, &c->plant); }},
      {"storage", [](SectionReader& r, Config* c) { ReadStorage(r, &c->storage); }},
      {"poll", [](SectionReader& r, Config* c) { ReadPoll(r, &c->poll); }},
      {"calibration", [](SectionReader& r, Config* c) { ReadCalibration(r, &c->calibration); }},
      {"forecast", [](SectionReader& r, Config* c) { ReadForecast(r, &c->forecast); }},
      {"diagnosis", [](SectionReader& r, Config* c) { ReadDiagnosis(r, &c->diagnosis); }},
      {"log", [](SectionReader& r, Config* c) { ReadLog(r, &c->log); }},
      {"monitor", [](SectionReader& r, Config* c) { ReadMonitor(r, &c->monitor); }},
      {"sim", [](SectionReader& r, Config* c) { ReadSim(r, &c->sim); }},
      {"upload", [](SectionReader& r, Config* c) { ReadUpload(r, &c->upload); }},
  };

  if (!root.contains("plant")) {
    errors->push_back({file, 0, "plant", "", "required section missing"});
  }

  for (const auto& [key, node] : root) {
    const std::string_view name = key.str();
    // [[modbus.device]] and [[modbus.point]]: the register map.
    if (name == "modbus") {
      ReadModbusSection(node, source, file, &config->modbus, errors);
      continue;
    }
    const auto* section = std::find_if(std::begin(kSections), std::end(kSections),
                                       [&](const Section& s) { return s.name == name; });
    const int line = static_cast<int>(node.source().begin.line);
    if (section == std::end(kSections)) {
      const std::string value = node.is_table() ? "" : source.Quote(node.source());
      errors->push_back({file, line, std::string(name), value,
                         node.is_table() ? "unknown section" : "unknown key"});
      continue;
    }
    const toml::table* table = node.as_table();
    if (table == nullptr) {
      errors->push_back({file, line, std::string(name), source.Quote(node.source()),
                         "expected a table ([" + std::string(name) + "])"});
      continue;
    }
    SectionReader reader(*table, source, file, errors);
    section->read(reader, config);
    reader.ReportUnknownKeys();
  }
}

}  // namespace

bool ParseClockTime(std::string_view text, int* hour, int* minute) {
  const auto digit = [&](std::size_t i) { return text[i] >= '0' && text[i] <= '9'; };
  if (text.size() != 5 || text[2] != ':' || !digit(0) || !digit(1) || !digit(3) || !digit(4)) {
    return false;
  }
  const int h = (text[0] - '0') * 10 + (text[1] - '0');
  const int m = (text[3] - '0') * 10 + (text[4] - '0');
  if (h > 23 || m > 59) return false;
  *hour = h;
  *minute = m;
  return true;
}

bool TimeZoneExists(const std::string& iana) {
  if (iana.empty() || iana.front() == '/' || iana.find("..") != std::string::npos) return false;
  const char* dir = std::getenv("TZDIR");
  const std::string path = std::string(dir && *dir ? dir : "/usr/share/zoneinfo") + "/" + iana;
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool ParseConfig(std::string_view toml_text, const std::string& path_for_messages, Config* out,
                 Diagnostics* errors) {
  assert(out != nullptr && errors != nullptr);
  Diagnostics found;
  toml::table root;
  try {
    root = toml::parse(toml_text, std::string_view(path_for_messages));
  } catch (const toml::parse_error& e) {
    const toml::source_position where = e.source().begin;
    errors->push_back({path_for_messages, static_cast<int>(where.line), "", "",
                       "TOML syntax error at column " + std::to_string(where.column) + ": " +
                           std::string(e.description())});
    return false;
  }
  Config config;
  config.source_path = path_for_messages;
  ReadDocument(root, SourceText(toml_text), path_for_messages, &config, &found);
  // Volume-flow points feed flow_kg_s through the plant's fluid density.
  for (ModbusPoint& point : config.modbus.points) {
    point.fluid_density_kg_m3 = config.plant.fluid_density_kg_m3;
  }
  // toml++ keeps keys sorted by name; report in file order instead.
  std::stable_sort(found.begin(), found.end(),
                   [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
  if (!found.empty()) {
    errors->insert(errors->end(), found.begin(), found.end());
    return false;
  }
  *out = std::move(config);
  return true;
}

bool LoadConfig(const std::string& path, Config* out, Diagnostics* errors) {
  assert(out != nullptr && errors != nullptr);
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    errors->push_back({path, 0, "", "", std::string("cannot open: ") + std::strerror(errno)});
    return false;
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    errors->push_back({path, 0, "", "", "read error"});
    return false;
  }
  return ParseConfig(text.str(), path, out, errors);
}

}  // namespace pvtwin
