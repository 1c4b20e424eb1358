// Bounded waiting for tests that watch real processes: poll a condition
// every 50 ms of wall time, never longer than the timeout.
#pragma once

#include <chrono>
#include <functional>
#include <thread>

#include "core/common/clock.h"

namespace pvtwin::testing {

// True as soon as done() is; false if it is still false after timeout_s.
inline bool WaitFor(double timeout_s, const std::function<bool()>& done) {
  const double deadline = WallNowS() + timeout_s;
  while (WallNowS() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

}  // namespace pvtwin::testing
