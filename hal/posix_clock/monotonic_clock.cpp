// CLOCK_MONOTONIC: now, and absolute sleeps.
#include "hal/posix_clock/monotonic_clock.hpp"

#include <cerrno>

namespace stencil::hal::posix_clock {

namespace {
constexpr MonotonicNs kNsPerS = 1'000'000'000;
}

MonotonicNs monotonic_now_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<MonotonicNs>(now.tv_sec) * kNsPerS + now.tv_nsec;
}

timespec monotonic_timespec(MonotonicNs deadline_ns) {
  return {static_cast<time_t>(deadline_ns / kNsPerS), static_cast<long>(deadline_ns % kNsPerS)};
}

void sleep_until_monotonic_ns(MonotonicNs deadline_ns) {
  if (deadline_ns <= 0) {
    return;
  }
  const timespec deadline = monotonic_timespec(deadline_ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
}

}  // namespace stencil::hal::posix_clock
