// The rig's Clock: CLOCK_MONOTONIC, absolute sleeps; and the same two calls as plain functions, the
// one place the process reads and sleeps on CLOCK_MONOTONIC (the threads that run on the wall clock
// and hold no Clock: the cycle's runner, the simulated device, the fake CY545, the journal's waits).
#pragma once

#include <ctime>

#include "hal/clock.hpp"

namespace stencil::hal::posix_clock {

// CLOCK_MONOTONIC in ns. Real-time safe (the vDSO: no system call, no allocation, no lock).
[[nodiscard]] MonotonicNs monotonic_now_ns();

// Blocks until CLOCK_MONOTONIC reaches deadline_ns: an absolute clock_nanosleep, resumed after a
// signal; at once when the deadline has passed (0 or below: no call at all).
void sleep_until_monotonic_ns(MonotonicNs deadline_ns);

// deadline_ns as the timespec of the POSIX calls that take an absolute CLOCK_MONOTONIC deadline
// (sem_clockwait, pthread_cond_clockwait). deadline_ns must not be negative.
[[nodiscard]] timespec monotonic_timespec(MonotonicNs deadline_ns);

class MonotonicClock final : public Clock {
 public:
  [[nodiscard]] MonotonicNs now_ns() const override { return monotonic_now_ns(); }
  void sleep_until_ns(MonotonicNs deadline_ns) override { sleep_until_monotonic_ns(deadline_ns); }
};

}  // namespace stencil::hal::posix_clock
