// The rig's Clock: CLOCK_MONOTONIC, absolute sleeps.
#pragma once

#include "hal/clock.hpp"

namespace stencil::hal::posix_clock {

class MonotonicClock final : public Clock {
 public:
  [[nodiscard]] MonotonicNs now_ns() const override;
  // clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME), resumed after a signal.
  void sleep_until_ns(MonotonicNs deadline_ns) override;
};

}  // namespace stencil::hal::posix_clock
