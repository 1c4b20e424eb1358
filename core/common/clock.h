// Time for the daemon, the poller and the plant simulator: real, or scaled.
//
// A ScaledClock maps wall time to simulated unix time:
//   t_sim = sim_start_s + (t_wall − wall_anchor_s) · speed
// Two processes given the same (sim_start_s, wall_anchor_s, speed) agree on
// the simulated time, which is how `pvtwin demo` runs the simulator and the
// daemon on one accelerated clock. speed = 1 with sim_start_s = wall_anchor_s
// is real time.
#pragma once

#include <atomic>
#include <chrono>
#include <thread>

namespace pvtwin {

class Clock {
 public:
  virtual ~Clock() = default;
  // Simulated (or real) unix time in seconds.
  virtual double NowS() const = 0;
  // Sleeps until NowS() >= t_s or *stop becomes true (checked at least every
  // 50 ms of wall time). Returns false when stopped early.
  virtual bool SleepUntil(double t_s, const std::atomic<bool>& stop) const = 0;
};

// Seconds of the steady clock since start (for durations, progress, ETAs).
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

inline double WallNowS() {
  using namespace std::chrono;
  return duration<double>(system_clock::now().time_since_epoch()).count();
}

class ScaledClock final : public Clock {
 public:
  // Real time.
  ScaledClock() : ScaledClock(WallNowS(), 0.0, 1.0) {}
  // wall_anchor_s = 0 means "now".
  ScaledClock(double sim_start_s, double wall_anchor_s, double speed)
      : sim_start_s_(sim_start_s),
        wall_anchor_s_(wall_anchor_s > 0 ? wall_anchor_s : WallNowS()),
        speed_(speed) {}

  double NowS() const override { return sim_start_s_ + (WallNowS() - wall_anchor_s_) * speed_; }

  bool SleepUntil(double t_s, const std::atomic<bool>& stop) const override {
    for (;;) {
      if (stop.load()) return false;
      const double wall_left_s = (t_s - NowS()) / speed_;
      if (wall_left_s <= 0) return true;
      const double nap_s = wall_left_s < 0.05 ? wall_left_s : 0.05;
      std::this_thread::sleep_for(std::chrono::duration<double>(nap_s));
    }
  }

  double speed() const { return speed_; }

 private:
  double sim_start_s_;
  double wall_anchor_s_;
  double speed_;
};

}  // namespace pvtwin
