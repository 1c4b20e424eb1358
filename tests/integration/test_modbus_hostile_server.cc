// Integration against a Modbus TCP server the project did not build on
// libmodbus: a raw-socket server in this test (loopback, its own thread) that
// answers the real ModbusPoller's reads correctly, then for a few periods with
// one crafted fault, then correctly again. The faults are what libmodbus
// 3.1.6 lets through (issue 17): another unit id (a gateway answering for
// another slave), protocol id 7, MBAP length 65535, MBAP length 0.
//
// The map is the collector of config/examples/sim-plant.toml (every register
// type and word order; two reads: input 0+16 and holding 100+1), the clock is
// stepped by the test one period at a time, and the test waits for each
// period's poll before the next step, so every period is known to have been
// answered correctly or with the fault (no ambiguous periods).
//
// Checks: a faulted period never yields a value (missing or rejected); every
// faulted reply is counted in DeviceStats::bad_replies, none as a timeout (a
// length of 65535 is refused from the header, not waited for); the reason is
// logged once with host, unit and read; after the fault the poller reconnects
// within the backoff and stores exactly the served values again.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <mutex>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "config/plant_config.h"
#include "io/modbus/modbus_poller.h"
#include "io/sim/modbus_sim_server.h"
#include "io/modbus/register_codec.h"
#include "tests/support/files.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

constexpr double kHostilePeriodS = 5.0;
constexpr std::int64_t kStartS = 1718964000;  // 2024-06-21T10:00:00Z

enum class Reply { kCorrect, kWrongUnit, kProtocolId7, kLength65535, kLength0 };

struct HostileCase {
  const char* name;
  Reply fault;
  const char* reason;  // what the poller must log
};

const HostileCase kCases[] = {
    {"wrong_unit", Reply::kWrongUnit, "reply unit id 7, expected 1"},
    {"protocol_id_7", Reply::kProtocolId7, "reply protocol id 7, expected 0"},
    {"length_65535", Reply::kLength65535, "reply MBAP length 65535, expected 2..254"},
    {"length_0", Reply::kLength0, "reply MBAP length 0, expected 2..254"},
};

void PrintTo(const HostileCase& c, std::ostream* os) { *os << c.name; }

// Applies a fault to a correct reply ADU.
void Corrupt(Reply fault, std::vector<std::uint8_t>* adu) {
  std::vector<std::uint8_t>& b = *adu;
  switch (fault) {
    case Reply::kCorrect:
      break;
    case Reply::kWrongUnit:
      b[6] = static_cast<std::uint8_t>(b[6] + 6);  // unit 1 answered as unit 7
      break;
    case Reply::kProtocolId7:
      b[2] = 0x00;
      b[3] = 0x07;
      break;
    case Reply::kLength65535:
      b[4] = 0xFF;
      b[5] = 0xFF;
      break;
    case Reply::kLength0:
      b[4] = 0x00;
      b[5] = 0x00;
      break;
  }
}

// A Modbus TCP server written from the protocol, on 127.0.0.1 (ephemeral
// port): function 3 and 4 from two register tables, every reply passed
// through the current fault. Any number of clients, one request at a time each.
class HostileServer {
 public:
  HostileServer() {
    listen_fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const int one = 1;
    setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        listen(listen_fd_, 8) != 0) {
      return;
    }
    socklen_t len = sizeof addr;
    getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
    thread_ = std::thread([this] { Serve(); });
  }
  ~HostileServer() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
    for (const Client& c : clients_) close(c.fd);
    close(listen_fd_);
  }
  HostileServer(const HostileServer&) = delete;
  HostileServer& operator=(const HostileServer&) = delete;

  int port() const { return port_; }
  std::uint64_t fault_replies() const { return fault_replies_.load(); }

  // The fault and the register tables (input, holding) for the next requests.
  void Set(Reply mode, const std::vector<std::uint16_t>& input,
           const std::vector<std::uint16_t>& holding) {
    std::lock_guard<std::mutex> lock(mutex_);
    mode_ = mode;
    input_ = input;
    holding_ = holding;
  }

 private:
  struct Client {
    int fd = -1;
    std::vector<std::uint8_t> pending;  // request bytes received so far
  };

  void Serve() {
    while (!stop_.load()) {
      std::vector<pollfd> fds = {{listen_fd_, POLLIN, 0}};
      for (const Client& c : clients_) fds.push_back({c.fd, POLLIN, 0});
      if (poll(fds.data(), fds.size(), 20) <= 0) continue;
      std::vector<Client> keep;
      for (std::size_t i = 1; i < fds.size(); ++i) {
        Client& c = clients_[i - 1];
        if (fds[i].revents == 0 || Receive(&c)) {
          keep.push_back(std::move(c));
        } else {
          close(c.fd);
        }
      }
      if (fds[0].revents & POLLIN) {
        const int fd = accept(listen_fd_, nullptr, nullptr);
        if (fd >= 0) keep.push_back({fd, {}});
      }
      clients_ = std::move(keep);
    }
  }

  // Reads what arrived and answers every complete 12-byte request; false
  // when the client closed.
  bool Receive(Client* c) {
    std::array<std::uint8_t, 512> buf{};
    const ssize_t n = recv(c->fd, buf.data(), buf.size(), 0);
    if (n <= 0) return false;
    c->pending.insert(c->pending.end(), buf.begin(), buf.begin() + n);
    while (c->pending.size() >= 12) {
      const std::vector<std::uint8_t> request(c->pending.begin(), c->pending.begin() + 12);
      c->pending.erase(c->pending.begin(), c->pending.begin() + 12);
      const std::vector<std::uint8_t> reply = Answer(request);
      if (send(c->fd, reply.data(), reply.size(), MSG_NOSIGNAL) !=
          static_cast<ssize_t>(reply.size())) {
        return false;
      }
    }
    return true;
  }

  std::vector<std::uint8_t> Answer(const std::vector<std::uint8_t>& q) {
    std::lock_guard<std::mutex> lock(mutex_);
    const int function = q[7];
    const std::size_t address = static_cast<std::size_t>((q[8] << 8) | q[9]);
    const std::size_t count = static_cast<std::size_t>((q[10] << 8) | q[11]);
    const std::vector<std::uint16_t>& table = function == 4 ? input_ : holding_;
    std::vector<std::uint8_t> r = {q[0], q[1], 0, 0, 0, 0, q[6], q[7]};
    if ((function != 3 && function != 4) || address + count > table.size()) {
      r[7] = static_cast<std::uint8_t>(function | 0x80);
      r.push_back(function == 3 || function == 4 ? 2 : 1);
    } else {
      r.push_back(static_cast<std::uint8_t>(2 * count));
      for (std::size_t i = 0; i < count; ++i) {
        r.push_back(static_cast<std::uint8_t>(table[address + i] >> 8));
        r.push_back(static_cast<std::uint8_t>(table[address + i] & 0xFF));
      }
    }
    r[5] = static_cast<std::uint8_t>(r.size() - 6);
    Corrupt(mode_, &r);
    if (mode_ != Reply::kCorrect) ++fault_replies_;
    return r;
  }

  int listen_fd_ = -1;
  int port_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::vector<Client> clients_;  // the server thread's
  std::mutex mutex_;             // guards mode_ and the tables
  Reply mode_ = Reply::kCorrect;
  std::vector<std::uint16_t> input_;
  std::vector<std::uint16_t> holding_;
  std::atomic<std::uint64_t> fault_replies_{0};
};

// The collector of the example map, pointed at the hostile server.
ModbusConfig CollectorMap(int port) {
  const fs::path path = fs::path(PVTWIN_SCENARIO_DIR) / "../../../config/examples/sim-plant.toml";
  Config config;
  Diagnostics errors;
  EXPECT_TRUE(ParseConfig(testing::ReadFile(path), path.string(), &config, &errors));
  ModbusConfig map;
  map.devices.push_back(config.modbus.devices.at(0));
  map.devices[0].host = "127.0.0.1";
  map.devices[0].port = port;
  map.devices[0].timeout_ms = 300;
  for (const ModbusPoint& p : config.modbus.points) {
    if (p.device == 0) map.points.push_back(p);
  }
  return map;
}

// A wire value inside the point's valid range that changes with the step.
double ServedValue(const ModbusPoint& p, int step) {
  const double lo = std::isfinite(p.valid_min) ? p.valid_min : 0.0;
  const double hi = std::isfinite(p.valid_max) ? p.valid_max : lo + 1000.0;
  return lo + (hi - lo) * (0.2 + 0.05 * (step % 10));
}

struct Tables {
  std::vector<std::uint16_t> input = std::vector<std::uint16_t>(128);
  std::vector<std::uint16_t> holding = std::vector<std::uint16_t>(128);
};

Tables TablesAt(const ModbusConfig& map, int step) {
  Tables t;
  for (const ModbusPoint& p : map.points) {
    std::vector<std::uint16_t>& table = p.table == RegisterTable::kInput ? t.input : t.holding;
    EncodePoint(
        p, ServedValue(p, step),
        std::span<std::uint16_t>(table.data() + p.address, static_cast<std::size_t>(p.Count())));
  }
  return t;
}

// The channel value the poller must store for point p at a step.
double Expected(const ModbusPoint& p, const Tables& t) {
  const std::vector<std::uint16_t>& table = p.table == RegisterTable::kInput ? t.input : t.holding;
  const DecodedValue v =
      DecodePoint(p, std::span<const std::uint16_t>(table.data() + p.address,
                                                    static_cast<std::size_t>(p.Count())));
  return WireToChannelUnit(p.channel, v.value);
}

bool WaitFor(const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return done();
}

class ModbusHostileServer : public ::testing::TestWithParam<HostileCase> {};

TEST_P(ModbusHostileServer, FaultedRepliesAreNeverStoredAndThePollerRecovers) {
  const HostileCase& hc = GetParam();
  HostileServer server;
  ASSERT_GT(server.port(), 0) << "cannot listen on loopback";
  const ModbusConfig map = CollectorMap(server.port());
  ASSERT_FALSE(map.points.empty());

  // Steps 1-3 correct, 4-7 the fault, 8-14 correct; one period each.
  constexpr int kFaultFrom = 4;
  constexpr int kFaultTo = 7;
  constexpr int kSteps = 14;
  const auto mode_at = [&](int step) {
    return step >= kFaultFrom && step <= kFaultTo ? hc.fault : Reply::kCorrect;
  };

  SteppedClock clock(static_cast<double>(kStartS));
  PollerOptions options;
  options.period_s = kHostilePeriodS;
  options.backoff_max_periods = 2;
  std::mutex mutex;
  std::vector<Sample> samples;
  std::vector<std::string> log;
  ModbusPoller poller(map, options, clock, [&](int priority, const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex);
    log.push_back("<" + std::to_string(priority) + ">" + text);
  });
  const auto polls = [&] { return poller.Stats().at(0).polls; };
  poller.Start([&](const Sample& s) {
    std::lock_guard<std::mutex> lock(mutex);
    samples.push_back(s);
  });
  std::vector<Tables> served(kSteps + 2);
  for (int step = 1; step <= kSteps + 1; ++step) {
    served[static_cast<std::size_t>(step)] = TablesAt(map, step);
    const Tables& t = served[static_cast<std::size_t>(step)];
    server.Set(mode_at(step), t.input, t.holding);
    clock.Advance(kHostilePeriodS);
    ASSERT_TRUE(WaitFor([&] { return polls() >= static_cast<std::uint64_t>(step); }))
        << "step " << step << ": the period was not polled";
  }
  ASSERT_TRUE(WaitFor([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return samples.size() >= static_cast<std::size_t>(kSteps);
  }));
  poller.Stop();

  std::lock_guard<std::mutex> lock(mutex);
  std::string log_text;
  for (const std::string& l : log) log_text += l + "\n";
  if (std::getenv("PVTWIN_SHOW_LOG") != nullptr) std::cerr << log_text;
  SCOPED_TRACE("poller log:\n" + log_text);
  int first_back = 0;  // first step after the fault with every value back
  for (const Sample& s : samples) {
    const int step = static_cast<int>((s.ts_s - kStartS) / 5);
    if (step < 1 || step > kSteps) continue;
    const Tables& t = served[static_cast<std::size_t>(step)];
    const bool faulted = mode_at(step) != Reply::kCorrect;
    int values = 0;
    for (const ModbusPoint& p : map.points) {
      if (s.Has(p.channel)) ++values;
      if (faulted) {
        EXPECT_FALSE(s.Has(p.channel)) << "step " << step << " " << ChannelName(p.channel) << " = "
                                       << s.Get(p.channel) << " from a faulted reply";
      } else if (s.Has(p.channel)) {
        EXPECT_EQ(s.Get(p.channel), Expected(p, t))
            << "step " << step << " " << ChannelName(p.channel);
      }
    }
    const bool all = values == static_cast<int>(map.points.size());
    if (step < kFaultFrom) {
      EXPECT_TRUE(all) << "step " << step << " before the fault";
    }
    if (step > kFaultTo && all && first_back == 0) first_back = step;
    if (step > kFaultTo && first_back != 0) {
      EXPECT_TRUE(all) << "step " << step << ": values missing again after the recovery";
    }
  }
  EXPECT_NE(first_back, 0) << "the poller never recovered";
  EXPECT_LE(first_back, kFaultTo + 1 + options.backoff_max_periods) << "recovery too slow";

  const DeviceStats st = poller.Stats().at(0);
  EXPECT_GE(server.fault_replies(), 2u) << "the fault was not exercised";
  EXPECT_EQ(st.bad_replies, server.fault_replies()) << "every faulted reply counted";
  EXPECT_EQ(st.timeouts, 0u) << "a faulted reply must be refused, not waited for";
  EXPECT_NE(st.last_error.find(hc.reason), std::string::npos) << st.last_error;

  // The reason logged once (one state change), with host, unit and read.
  const std::string who = "127.0.0.1:" + std::to_string(server.port()) + " unit 1";
  int reason_lines = 0;
  for (const std::string& l : log) {
    if (l.find(hc.reason) == std::string::npos) continue;
    ++reason_lines;
    EXPECT_NE(l.find(who), std::string::npos) << l;
    EXPECT_NE(l.find("read input 0+16"), std::string::npos) << l;
  }
  EXPECT_EQ(reason_lines, 1);
}

INSTANTIATE_TEST_SUITE_P(Faults, ModbusHostileServer, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<HostileCase>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace pvtwin
