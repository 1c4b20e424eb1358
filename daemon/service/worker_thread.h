// Pieces shared by the daemon's background workers (the upload, the
// weather fetch): a stop request a worker waits on, and the exponential
// backoff between retries of a remote service.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>

namespace pvtwin {

// Set once by the daemon's thread; the worker sleeps on it and polls it.
class StopRequest {
 public:
  void Set() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    flag_ = true;
    wake_.notify_all();
  }
  bool IsSet() const { return flag_.load(); }
  // For calls that poll a flag during long operations (io/weather/http_client.h).
  const std::atomic<bool>* Flag() const { return &flag_; }
  // Sleeps s seconds or until Set; true when stopped.
  bool WaitFor(double s) {
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, std::chrono::duration<double>(s), [this] { return stop_; });
    return stop_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::atomic<bool> flag_{false};
};

// Retry delays first_s, 2·first_s, 4·first_s, … up to cap_s; Reset after a
// success.
class Backoff {
 public:
  Backoff(double first_s, double cap_s) : first_s_(first_s), cap_s_(cap_s), next_s_(first_s) {}
  // The delay to wait now; the next one doubles.
  double Next() {
    const double now_s = next_s_;
    next_s_ = std::min(2.0 * next_s_, cap_s_);
    return now_s;
  }
  void Reset() { next_s_ = first_s_; }

 private:
  double first_s_, cap_s_, next_s_;
};

}  // namespace pvtwin
