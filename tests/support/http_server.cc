#include "tests/support/http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace pvtwin::testing {

namespace {

const char* Reason(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 400:
      return "Bad Request";
    case 404:
      return "Not Found";
    case 500:
      return "Internal Server Error";
    case 503:
      return "Service Unavailable";
    default:
      return "Status";
  }
}

void SendAll(int fd, const std::string& data) {
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;  // the client went away
    sent += static_cast<std::size_t>(n);
  }
}

}  // namespace

bool LoopbackHttpServer::Start(int port, std::string* error) {
  Stop();
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
  const int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(listen_fd_, 8) != 0) {
    *error =
        std::string("bind/listen 127.0.0.1:") + std::to_string(port) + ": " + std::strerror(errno);
    ::close(listen_fd_);
    listen_fd_ = -1;
    return false;
  }
  socklen_t len = sizeof addr;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  stop_ = false;
  thread_ = std::thread([this] { Serve(); });
  return true;
}

void LoopbackHttpServer::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
}

void LoopbackHttpServer::SetAnswer(const std::string& path, const Answer& answer) {
  std::lock_guard lock(mutex_);
  answers_[path] = answer;
}

std::string LoopbackHttpServer::last_target() const {
  std::lock_guard lock(mutex_);
  return last_target_;
}

int LoopbackHttpServer::FreePort() {
  LoopbackHttpServer probe;
  std::string error;
  if (!probe.Start(0, &error)) return 0;
  const int port = probe.port();
  probe.Stop();
  return port;
}

bool LoopbackHttpServer::Sleep(double s) const {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
  while (std::chrono::steady_clock::now() < until) {
    if (stop_) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return !stop_;
}

void LoopbackHttpServer::Serve() {
  while (!stop_) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    const int fd = ::accept(listen_fd_, nullptr, nullptr);
    if (fd < 0) continue;
    Answer1(fd);
    ::close(fd);
  }
}

void LoopbackHttpServer::Answer1(int fd) {
  // The request head, up to the blank line (a GET has no body).
  std::string head;
  char buf[2048];
  while (head.find("\r\n\r\n") == std::string::npos && head.size() < 65536) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 2000) <= 0) return;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) return;
    head.append(buf, static_cast<std::size_t>(n));
  }
  // "GET /path?query HTTP/1.1"
  const std::size_t sp1 = head.find(' ');
  const std::size_t sp2 = head.find(' ', sp1 + 1);
  const std::string target = head.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string path = target.substr(0, target.find('?'));
  Answer answer;
  answer.status = 404;
  answer.body = "{\"error\":true,\"reason\":\"no such path\"}";
  {
    std::lock_guard lock(mutex_);
    last_target_ = target;
    const auto it = answers_.find(path);
    if (it != answers_.end()) answer = it->second;
  }
  ++requests_;
  if (answer.delay_s > 0.0 && !Sleep(answer.delay_s)) return;
  std::string response = "HTTP/1.1 " + std::to_string(answer.status) + " " + Reason(answer.status) +
                         "\r\nContent-Type: " + answer.content_type +
                         "\r\nContent-Length: " + std::to_string(answer.body.size()) +
                         "\r\nConnection: close\r\n\r\n";
  response += answer.truncate ? answer.body.substr(0, answer.body.size() / 2) : answer.body;
  SendAll(fd, response);
}

}  // namespace pvtwin::testing
