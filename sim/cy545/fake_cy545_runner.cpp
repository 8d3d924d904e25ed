// The real-time servicing thread of the fake CY545.
#include "sim/cy545/fake_cy545_runner.hpp"

#include <poll.h>
#include <time.h>

namespace stencil::sim::cy545 {

namespace {
constexpr int kServicePeriodMs = 1;
}

FakeCy545Runner::FakeCy545Runner(FakeCy545& fake) : fake_(fake), thread_([this] { run(); }) {}

FakeCy545Runner::~FakeCy545Runner() {
  stop_.store(true);
  thread_.join();
}

void FakeCy545Runner::run() {
  while (!stop_.load()) {
    int fd = -1;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      fake_.step(hal::posix_clock::monotonic_now_ns());
      fd = fake_.master_fd();
    }
    if (fd >= 0) {
      // Wakes on the driver's bytes, or after a period to issue the steps that have fallen due.
      pollfd request{fd, POLLIN, 0};
      static_cast<void>(poll(&request, 1, kServicePeriodMs));
    } else {
      const timespec period{0, kServicePeriodMs * 1'000'000L};
      nanosleep(&period, nullptr);
    }
  }
}

}  // namespace stencil::sim::cy545
