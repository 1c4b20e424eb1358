#include "io/sim/modbus_sim_server.h"

#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/data/qc.h"
#include "io/modbus/register_codec.h"

namespace pvtwin {

namespace {

constexpr std::array<std::pair<std::string_view, FaultKind>, 9> kFaultNames = {{
    {"drop", FaultKind::kDrop},
    {"exception", FaultKind::kException},
    {"delay", FaultKind::kDelay},
    {"nan", FaultKind::kNan},
    {"range", FaultKind::kRange},
    {"freeze", FaultKind::kFreeze},
    {"stray", FaultKind::kStray},
    {"wrong_unit", FaultKind::kWrongUnit},
    {"glitch", FaultKind::kGlitch},
}};

bool ParseNumber(std::string_view text, double* out) {
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *out);
  return result.ec == std::errc() && result.ptr == text.data() + text.size() && std::isfinite(*out);
}

std::vector<std::string_view> Split(std::string_view text, char sep) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = text.find(sep, start);
    parts.push_back(text.substr(start, end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return parts;
}

// The raw value a "nan" fault sends for a point.
double NanRaw(const ModbusPoint& p) {
  if (p.type == RegisterType::kF32 || p.type == RegisterType::kF64) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (p.nan_value) return *p.nan_value;
  return 1e300;  // clamped to the type's largest value
}

// The value (wire unit) a "range" fault sends for a point.
double OutOfRangeValue(const ModbusPoint& p) {
  if (std::isfinite(p.valid_max) && std::isfinite(p.valid_min)) {
    return p.valid_max + (p.valid_max - p.valid_min);
  }
  return std::isfinite(p.valid_max) ? p.valid_max + 1e3 : 1e9;
}

}  // namespace

bool ParseFault(std::string_view text, Fault* fault, std::string* error) {
  const std::string rule =
      "expected DEVICE:KIND:from=S:for=S[:ms=N] with KIND one of drop, "
      "exception, delay, nan, range, freeze, stray, wrong_unit, glitch";
  const std::vector<std::string_view> parts = Split(text, ':');
  if (parts.size() < 4 || parts[0].empty()) {
    *error = "fault '" + std::string(text) + "': " + rule;
    return false;
  }
  Fault f;
  f.device = std::string(parts[0]);
  const auto kind = std::find_if(kFaultNames.begin(), kFaultNames.end(),
                                 [&](const auto& n) { return n.first == parts[1]; });
  if (kind == kFaultNames.end()) {
    *error =
        "fault '" + std::string(text) + "': unknown kind '" + std::string(parts[1]) + "'; " + rule;
    return false;
  }
  f.kind = kind->second;
  bool has_from = false;
  bool has_for = false;
  for (std::size_t i = 2; i < parts.size(); ++i) {
    const std::size_t eq = parts[i].find('=');
    const std::string_view key = parts[i].substr(0, eq);
    double value = 0;
    if (eq == std::string_view::npos || !ParseNumber(parts[i].substr(eq + 1), &value)) {
      *error =
          "fault '" + std::string(text) + "': '" + std::string(parts[i]) + "' is not key=number";
      return false;
    }
    if (key == "from" && value >= 0) {
      f.from_s = value;
      has_from = true;
    } else if (key == "for" && value > 0) {
      f.for_s = value;
      has_for = true;
    } else if (key == "ms" && value >= 0 && value <= 600000) {
      f.delay_ms = static_cast<int>(value);
    } else {
      *error = "fault '" + std::string(text) + "': '" + std::string(parts[i]) +
               "': from >= 0, for > 0, ms in [0, 600000]";
      return false;
    }
  }
  if (!has_from || !has_for) {
    *error = "fault '" + std::string(text) + "': from= and for= are required; " + rule;
    return false;
  }
  *fault = f;
  return true;
}

bool SteppedClock::SleepUntil(double t_s, const std::atomic<bool>& stop) const {
  while (NowS() < t_s) {
    if (stop.load()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

struct ModbusSimServer::Device {
  std::size_t index = 0;
  ModbusDevice config;
  std::vector<std::size_t> points;
  modbus_t* ctx = nullptr;
  modbus_mapping_t* mapping = nullptr;
  int listen_fd = -1;
  int port = 0;
  std::vector<int> clients;
  // Fault state, touched only by the device's thread.
  unsigned active_faults = 0;  // bit per FaultKind, for the log
  bool frozen = false;
  Sample frozen_sample;

  ~Device() {
    for (int fd : clients) close(fd);
    if (listen_fd >= 0) close(listen_fd);
    if (mapping != nullptr) modbus_mapping_free(mapping);
    if (ctx != nullptr) {
      modbus_close(ctx);
      modbus_free(ctx);
    }
  }
};

ModbusSimServer::ModbusSimServer(const ModbusConfig& map, PlantSource* source, const Clock& clock,
                                 double start_s, SimServerOptions options, LogFn log)
    : map_(map),
      source_(source),
      clock_(clock),
      start_s_(start_s),
      options_(options),
      log_(std::move(log)) {}

ModbusSimServer::~ModbusSimServer() { Stop(); }

bool ModbusSimServer::Start(std::string* error) {
  for (std::size_t d = 0; d < map_.devices.size(); ++d) {
    auto device = std::make_unique<Device>();
    device->index = d;
    device->config = map_.devices[d];
    int nb_input = 0;
    int nb_holding = 0;
    for (std::size_t i = 0; i < map_.points.size(); ++i) {
      const ModbusPoint& p = map_.points[i];
      if (p.device != d) continue;
      device->points.push_back(i);
      int& nb = p.table == RegisterTable::kInput ? nb_input : nb_holding;
      nb = std::max(nb, p.address + p.Count());
    }
    device->mapping = modbus_mapping_new(0, 0, nb_holding, nb_input);
    const ModbusDevice& c = device->config;
    if (c.IsRtu()) {
      device->ctx = modbus_new_rtu(c.serial.c_str(), c.baud, c.parity, c.data_bits, c.stop_bits);
      if (device->ctx == nullptr || modbus_set_slave(device->ctx, c.unit_id) != 0 ||
          modbus_connect(device->ctx) != 0) {
        *error = c.name + ": cannot open " + c.serial + ": " + modbus_strerror(errno);
        return false;
      }
    } else {
      in_addr addr{};
      if (inet_pton(AF_INET, c.host.c_str(), &addr) != 1) {
        *error = c.name + ": the simulator serves on IPv4 addresses only, not '" + c.host + "'";
        return false;
      }
      const int port = options_.ephemeral_ports ? 0 : c.port + options_.port_offset;
      device->ctx = modbus_new_tcp(c.host.c_str(), port);
      if (device->ctx != nullptr) device->listen_fd = modbus_tcp_listen(device->ctx, 16);
      if (device->listen_fd < 0) {
        *error = c.name + ": cannot listen on " + c.host + ":" + std::to_string(port) + ": " +
                 modbus_strerror(errno);
        return false;
      }
      sockaddr_in bound{};
      socklen_t len = sizeof bound;
      getsockname(device->listen_fd, reinterpret_cast<sockaddr*>(&bound), &len);
      device->port = ntohs(bound.sin_port);
    }
    devices_.push_back(std::move(device));
  }
  for (auto& device : devices_) threads_.emplace_back([this, d = device.get()] { Serve(d); });
  return true;
}

void ModbusSimServer::Stop() {
  stop_.store(true);
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  devices_.clear();
}

std::vector<std::string> ModbusSimServer::Endpoints() const {
  std::vector<std::string> lines;
  for (const auto& d : devices_) {
    lines.push_back(d->config.IsRtu() ? d->config.name + " rtu " + d->config.serial
                                      : d->config.name + " tcp " + d->config.host + ":" +
                                            std::to_string(d->port));
  }
  return lines;
}

int ModbusSimServer::Port(std::size_t device) const { return devices_.at(device)->port; }

bool ModbusSimServer::AddFault(const Fault& fault, std::string* error) {
  const bool known = std::any_of(map_.devices.begin(), map_.devices.end(),
                                 [&](const ModbusDevice& d) { return d.name == fault.device; });
  if (!known) {
    *error = "fault on unknown device '" + fault.device + "'";
    return false;
  }
  std::lock_guard<std::mutex> lock(faults_mutex_);
  faults_.push_back(fault);
  return true;
}

void ModbusSimServer::Serve(Device* device) {
  const bool rtu = device->config.IsRtu();
  std::array<std::uint8_t, MODBUS_TCP_MAX_ADU_LENGTH> query{};
  const int header = modbus_get_header_length(device->ctx);

  // Faults active now, one bit per kind, and the delay to apply.
  const auto active = [&](int* delay_ms) {
    const double since_start_s = clock_.NowS() - start_s_;
    unsigned bits = 0;
    std::lock_guard<std::mutex> lock(faults_mutex_);
    for (const Fault& f : faults_) {
      if (f.device != device->config.name) continue;
      if (since_start_s >= f.from_s && since_start_s < f.from_s + f.for_s) {
        bits |= 1u << static_cast<unsigned>(f.kind);
        if (f.kind == FaultKind::kDelay) *delay_ms = f.delay_ms;
      }
    }
    return bits;
  };
  const auto has = [](unsigned bits, FaultKind k) {
    return (bits >> static_cast<unsigned>(k)) & 1u;
  };
  const auto log_changes = [&](unsigned bits) {
    if (bits == device->active_faults) return;
    for (const auto& [name, kind] : kFaultNames) {
      if (has(bits, kind) != has(device->active_faults, kind)) {
        log_(kNotice, "sim " + device->config.name + ": fault " + std::string(name) +
                          (has(bits, kind) ? " begins" : " ends"));
      }
    }
    device->active_faults = bits;
  };

  // Answers one request (length n) on the device's current socket. Returns
  // false when the connection should be closed.
  const auto answer = [&](int n) {
    int delay_ms = 0;
    const unsigned faults = active(&delay_ms);
    log_changes(faults);
    if (has(faults, FaultKind::kDrop)) return false;
    ++requests_;
    const int function = query[static_cast<std::size_t>(header)];
    if (function != MODBUS_FC_READ_HOLDING_REGISTERS &&
        function != MODBUS_FC_READ_INPUT_REGISTERS) {
      modbus_reply_exception(device->ctx, query.data(), MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
      return true;
    }
    if (has(faults, FaultKind::kException)) {
      modbus_reply_exception(device->ctx, query.data(), MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
      return true;
    }
    if (has(faults, FaultKind::kDelay)) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(delay_ms);
      while (!stop_.load() && std::chrono::steady_clock::now() < until) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    Sample sample = source_->At(clock_.NowS());
    if (has(faults, FaultKind::kFreeze)) {
      if (!device->frozen) device->frozen_sample = sample;
      device->frozen = true;
      sample = device->frozen_sample;
    } else {
      device->frozen = false;
    }
    for (const std::size_t i : device->points) {
      const ModbusPoint& p = map_.points[i];
      std::uint16_t* table = p.table == RegisterTable::kInput ? device->mapping->tab_input_registers
                                                              : device->mapping->tab_registers;
      const std::span<std::uint16_t> words(table + p.address, static_cast<std::size_t>(p.Count()));
      if (has(faults, FaultKind::kNan)) {
        EncodeRaw(p.type, p.word_order, NanRaw(p), words);
      } else if (has(faults, FaultKind::kRange)) {
        EncodePoint(p, OutOfRangeValue(p), words);
      } else if (has(faults, FaultKind::kGlitch) && IsShortWave(p.channel)) {
        EncodePoint(p, ChannelToPointUnit(p, kGlitchWM2), words);
      } else {
        EncodePoint(p, ChannelToPointUnit(p, sample.Get(p.channel)), words);
      }
    }
    if (has(faults, FaultKind::kStray)) {
      // The reply copies these bytes from the request: the TCP transaction
      // id (bytes 0-1) or the RTU unit id (byte 0).
      query[0] = static_cast<std::uint8_t>(query[0] ^ 0x5A);
    }
    if (has(faults, FaultKind::kWrongUnit)) {
      // The reply copies the unit id from the request's byte before the
      // function code (TCP: the MBAP unit id; RTU: the slave address).
      const auto at = static_cast<std::size_t>(header - 1);
      query[at] = static_cast<std::uint8_t>(query[at] + 6);
    }
    modbus_reply(device->ctx, query.data(), n, device->mapping);
    return true;
  };

  while (!stop_.load()) {
    fd_set set;
    FD_ZERO(&set);
    int max_fd = -1;
    const auto watch = [&](int fd) {
      FD_SET(fd, &set);
      max_fd = std::max(max_fd, fd);
    };
    if (rtu) {
      watch(modbus_get_socket(device->ctx));
    } else {
      watch(device->listen_fd);
      for (int fd : device->clients) watch(fd);
    }
    timeval tv{0, 50000};
    if (select(max_fd + 1, &set, nullptr, nullptr, &tv) <= 0) continue;
    if (rtu) {
      const int n = modbus_receive(device->ctx, query.data());
      if (n > 0) answer(n);  // a dropped RTU device stays silent
      continue;
    }
    if (FD_ISSET(device->listen_fd, &set)) {
      const int fd = accept(device->listen_fd, nullptr, nullptr);
      int delay_ms = 0;
      const unsigned faults = active(&delay_ms);
      log_changes(faults);
      if (fd >= 0 && has(faults, FaultKind::kDrop)) {
        close(fd);
      } else if (fd >= 0) {
        device->clients.push_back(fd);
      }
    }
    std::vector<int> keep;
    for (int fd : device->clients) {
      bool open = true;
      if (FD_ISSET(fd, &set)) {
        modbus_set_socket(device->ctx, fd);
        const int n = modbus_receive(device->ctx, query.data());
        open = n >= 0 && (n == 0 || answer(n));
      }
      if (open) {
        keep.push_back(fd);
      } else {
        close(fd);
      }
    }
    device->clients = std::move(keep);
    modbus_set_socket(device->ctx, -1);
  }
}

}  // namespace pvtwin
