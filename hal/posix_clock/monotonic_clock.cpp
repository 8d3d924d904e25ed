// CLOCK_MONOTONIC behind the Clock interface.
#include "hal/posix_clock/monotonic_clock.hpp"

#include <cerrno>
#include <ctime>

namespace stencil::hal::posix_clock {

MonotonicNs MonotonicClock::now_ns() const {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<MonotonicNs>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

void MonotonicClock::sleep_until_ns(MonotonicNs deadline_ns) {
  if (deadline_ns <= 0) {
    return;
  }
  const timespec deadline{static_cast<time_t>(deadline_ns / 1'000'000'000), static_cast<long>(deadline_ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
}

}  // namespace stencil::hal::posix_clock
