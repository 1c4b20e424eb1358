// A small real HTTP/1.1 server on loopback for the weather-fetch tests:
// plain sockets, one thread, one connection at a time, `Connection: close`.
// Each path (without its query) has a canned answer: a status with a body
// (recorded Open-Meteo answers from tests/weather/data), an answer sent only
// after a delay (slower than a client's timeout), or a body cut short of its
// Content-Length (the connection closes mid-body). Paths without an answer
// get 404. Stop() closes the listener, so a client sees "connection
// refused"; Start() on the same port brings the server back.
#pragma once

#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace pvtwin::testing {

class LoopbackHttpServer {
 public:
  struct Answer {
    int status = 200;
    std::string body;
    std::string content_type = "application/json; charset=utf-8";
    double delay_s = 0.0;   // wait this long before answering
    bool truncate = false;  // send half the body, then close
  };

  LoopbackHttpServer() = default;
  ~LoopbackHttpServer() { Stop(); }
  LoopbackHttpServer(const LoopbackHttpServer&) = delete;
  LoopbackHttpServer& operator=(const LoopbackHttpServer&) = delete;

  // Listens on 127.0.0.1:port (0: a free port, see port()). False with
  // *error when the port cannot be bound.
  bool Start(int port, std::string* error);
  void Stop();
  int port() const { return port_; }
  std::string Url(const std::string& path_and_query) const {
    return "http://127.0.0.1:" + std::to_string(port_) + path_and_query;
  }

  void SetAnswer(const std::string& path, const Answer& answer);
  // Requests served so far (all paths), and the last request line's target.
  int requests() const { return requests_.load(); }
  std::string last_target() const;

  // A port that is free now (bound and released), for a server started later.
  static int FreePort();

 private:
  void Serve();
  void Answer1(int fd);
  // Sleeps s seconds or until Stop; false when stopped.
  bool Sleep(double s) const;

  int listen_fd_ = -1;
  int port_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<int> requests_{0};
  mutable std::mutex mutex_;
  std::map<std::string, Answer> answers_;
  std::string last_target_;
};

}  // namespace pvtwin::testing
