// Clock: the one source of time for the cycle and the links (wall time on the rig, a virtual clock
// in fast simulation and in tests).
#pragma once

#include <cstdint>

namespace stencil::hal {

// Nanoseconds on a monotonic clock with an arbitrary epoch. Never goes back.
using MonotonicNs = std::int64_t;
inline constexpr MonotonicNs kNsPerSecond = 1'000'000'000;

class Clock {
 public:
  Clock() = default;
  Clock(const Clock&) = delete;
  Clock& operator=(const Clock&) = delete;

  // Now. Real-time safe: no allocation, no lock, no blocking.
  [[nodiscard]] virtual MonotonicNs now_ns() const = 0;

  // Blocks until now_ns() >= deadline_ns (at once when it has passed). On the rig an absolute
  // clock_nanosleep on CLOCK_MONOTONIC, retried on EINTR; a virtual clock jumps to the deadline.
  // The only blocking call the cycle makes.
  virtual void sleep_until_ns(MonotonicNs deadline_ns) = 0;

 protected:
  // Not virtual, and not public: clocks are made by the board (statically) and never deleted
  // through this interface; a virtual destructor would pull operator delete into the core.
  ~Clock() = default;
};

}  // namespace stencil::hal
