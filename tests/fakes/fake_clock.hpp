// FakeClock: a hal::Clock that the test moves by hand, remembering every sleep the code under test
// asked for, for tests that must say what time a link or a cycle saw and how it waited.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "hal/clock.hpp"

namespace stencil::test {

// Unlike sim::VirtualClock (the simulation's clock, which only jumps), this double records each
// sleep's deadline and can run a hook while "asleep", so a test can play the other side of a link
// (publish a device sample, say) at the moment the code under test waits. Like every hal::Clock it
// never goes back: set_ns() and advance_ns() refuse to.
class FakeClock final : public hal::Clock {
 public:
  explicit FakeClock(hal::MonotonicNs start_ns = 0) : now_(start_ns) {}

  [[nodiscard]] hal::MonotonicNs now_ns() const override { return now_; }

  // Jumps to the deadline (stays when it has passed), records it, then runs on_sleep with the new now.
  void sleep_until_ns(hal::MonotonicNs deadline_ns) override {
    sleeps_.push_back(deadline_ns);
    if (deadline_ns > now_) now_ = deadline_ns;
    if (on_sleep) on_sleep(now_);
  }

  // Moves to `now_ns`; false (and the clock stays) when that would be earlier than now.
  bool set_ns(hal::MonotonicNs now_ns) {
    if (now_ns < now_) return false;
    now_ = now_ns;
    return true;
  }
  // Moves on by `dt_ns`; false (and the clock stays) for a negative step.
  bool advance_ns(hal::MonotonicNs dt_ns) { return set_ns(now_ + dt_ns); }
  bool advance_ms(std::int64_t ms) { return advance_ns(ms * 1'000'000); }

  // Every deadline passed to sleep_until_ns, in order (a deadline already past included).
  [[nodiscard]] const std::vector<hal::MonotonicNs>& sleeps() const { return sleeps_; }

  // Run after each sleep, with the time the sleeper wakes at.
  std::function<void(hal::MonotonicNs)> on_sleep;

 private:
  hal::MonotonicNs now_;
  std::vector<hal::MonotonicNs> sleeps_;
};

}  // namespace stencil::test
