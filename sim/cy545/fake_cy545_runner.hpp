// Runs a FakeCy545 in real time on a thread of its own: services the pty on CLOCK_MONOTONIC, about every
// millisecond and at once when bytes arrive. For tests and the host simulation that run on wall time.
#pragma once

#include <atomic>
#include <mutex>
#include <thread>

#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/cy545/fake_cy545.hpp"

namespace stencil::sim::cy545 {

class FakeCy545Runner {
 public:
  // Starts the thread. The fake must have been made with a start time from
  // hal::posix_clock::monotonic_now_ns(), the clock the thread steps it on.
  explicit FakeCy545Runner(FakeCy545& fake);
  // Stops and joins the thread.
  ~FakeCy545Runner();
  FakeCy545Runner(const FakeCy545Runner&) = delete;
  FakeCy545Runner& operator=(const FakeCy545Runner&) = delete;

  // Runs `inspect(fake)` with the servicing thread held off: the only safe way to read the fake's
  // state or pull a fault hook while the runner is running.
  template <typename Inspect>
  decltype(auto) with_fake(Inspect&& inspect) {
    const std::lock_guard<std::mutex> lock(mutex_);
    return inspect(fake_);
  }

 private:
  void run();

  FakeCy545& fake_;
  std::mutex mutex_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace stencil::sim::cy545
