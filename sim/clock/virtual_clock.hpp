// A Clock for fast, deterministic simulation and tests: time moves only when someone sleeps or the
// test advances it, so a simulated hour takes as long as its computation.
#pragma once

#include "hal/clock.hpp"

namespace stencil::sim {

class VirtualClock final : public hal::Clock {
 public:
  explicit VirtualClock(hal::MonotonicNs start_ns = 0) : now_(start_ns) {}

  [[nodiscard]] hal::MonotonicNs now_ns() const override { return now_; }
  // Jumps to the deadline (never back).
  void sleep_until_ns(hal::MonotonicNs deadline_ns) override { now_ = deadline_ns > now_ ? deadline_ns : now_; }
  void advance_ns(hal::MonotonicNs dt_ns) { now_ += dt_ns > 0 ? dt_ns : 0; }

 private:
  hal::MonotonicNs now_;
};

}  // namespace stencil::sim
