// Programmatic edits of a config text, for `pvtwin demo` and the end-to-end
// tests: point each Modbus device at the address a simulator listens on, and
// set daemon sections. The result is TOML text that LoadConfig reads
// (comments of the input are not kept).
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace pvtwin {

struct TcpEndpoint {
  std::string host;
  long port = 0;
};

// Device name → endpoint, from the simulator's "listening DEVICE tcp
// HOST:PORT" lines (other lines are ignored).
std::map<std::string, TcpEndpoint> ParseListeningLines(const std::vector<std::string>& lines);

struct DaemonSettings {
  std::string db_path;
  double poll_period_s = 5;
  std::string variant = "2N1Ccolwr";
  int window_days = 14;
  std::string calibrate_at = "02:00";
  std::string timezone = "UTC";
  double horizon_h = 24;
  double refresh_min = 60;
  // [forecast] weather fetch; left out of the config while weather_url is empty.
  std::string weather_url;
  double weather_refresh_min = 60;
  double weather_timeout_s = 30;
};

// `config_text` with every [[modbus.device]] moved to its endpoint and the
// [storage], [poll], [calibration] and [forecast] sections replaced. False
// with *error when the text does not parse or a device has no endpoint.
bool EditConfig(std::string_view config_text, const std::map<std::string, TcpEndpoint>& endpoints,
                const DaemonSettings& settings, std::string* out, std::string* error);

}  // namespace pvtwin
