#include "config/config_edit.h"

#include <toml++/toml.h>

#include <sstream>

namespace pvtwin {

std::map<std::string, TcpEndpoint> ParseListeningLines(const std::vector<std::string>& lines) {
  std::map<std::string, TcpEndpoint> endpoints;
  for (const std::string& line : lines) {
    std::istringstream in(line);
    std::string word, device, transport, address;
    if (!(in >> word >> device >> transport >> address) || word != "listening" ||
        transport != "tcp") {
      continue;
    }
    const std::size_t colon = address.rfind(':');
    if (colon == std::string::npos) continue;
    endpoints[device] = {address.substr(0, colon), std::stol(address.substr(colon + 1))};
  }
  return endpoints;
}

bool EditConfig(std::string_view config_text, const std::map<std::string, TcpEndpoint>& endpoints,
                const DaemonSettings& s, std::string* out, std::string* error) {
  toml::table config;
  try {
    config = toml::parse(config_text);
  } catch (const toml::parse_error& e) {
    *error = "config text: " + std::string(e.description());
    return false;
  }
  if (toml::array* devices = config["modbus"]["device"].as_array()) {
    for (toml::node& node : *devices) {
      toml::table* device = node.as_table();
      if (device == nullptr || device->contains("serial")) continue;
      const std::string name = (*device)["name"].value_or(std::string());
      const auto it = endpoints.find(name);
      if (it == endpoints.end()) {
        *error = "no TCP endpoint for device \"" + name + "\"";
        return false;
      }
      device->insert_or_assign("host", it->second.host);
      device->insert_or_assign("port", it->second.port);
    }
  }
  config.insert_or_assign("storage", toml::table{{"path", s.db_path}, {"raw_retention_days", 30}});
  config.insert_or_assign("poll", toml::table{{"period_s", s.poll_period_s}});
  config.insert_or_assign("calibration", toml::table{{"variant", s.variant},
                                                     {"window_days", s.window_days},
                                                     {"step_s", 60},
                                                     {"at", s.calibrate_at},
                                                     {"timezone", s.timezone}});
  toml::table forecast{{"horizon_h", s.horizon_h}, {"refresh_min", s.refresh_min}};
  if (!s.weather_url.empty()) {
    forecast.insert_or_assign("weather_url", s.weather_url);
    forecast.insert_or_assign("weather_refresh_min", s.weather_refresh_min);
    forecast.insert_or_assign("weather_timeout_s", s.weather_timeout_s);
  }
  config.insert_or_assign("forecast", std::move(forecast));
  std::ostringstream text;
  text << config << "\n";
  *out = text.str();
  return true;
}

}  // namespace pvtwin
