// FakeCy545Clock: the machine side's clock in fast simulation. Virtual time, which the fake CY545
// follows: whenever the driver looks at the time or sleeps, the fake runs to that time and answers
// what the driver wrote. Bytes take their wire time (ten bits each at the baud rate), so an update
// costs the time it would on the rig's serial line, and time always moves while the driver talks.
// One thread: the driver's and the fake's, taking turns; deterministic.
#pragma once

#include <cstdint>

#include "hal/clock.hpp"
#include "sim/cy545/fake_cy545.hpp"

namespace stencil::sim::cy545 {

class FakeCy545Clock final : public hal::Clock {
 public:
  // The fake's bytes take their wire time, and its commands the chip's time (Cy545Chip::kCommandTimeNs).
  FakeCy545Clock(FakeCy545& fake, hal::MonotonicNs start_ns, double baud)
      : fake_(fake), now_(start_ns), byte_ns_(static_cast<hal::MonotonicNs>(10.0 * 1e9 / baud)) {
    fake_.set_byte_time_ns(byte_ns_);
    fake_.chip().set_command_time_ns(Cy545Chip::kCommandTimeNs);
  }

  // Time passes by the wire time of every byte that crossed the line since the last look, and while
  // the driver waits on a chip that is busy (homing or moving) with a question in its buffer, until
  // the chip is free to answer it: on the rig the driver's wait for the reply is that time.
  [[nodiscard]] hal::MonotonicNs now_ns() const override {
    fake_.step(now_);
    for (int waited_ms = 0; waited_ms < kLongestWaitMs && fake_.chip().busy() && fake_.chip().receive_buffer_bytes() > 0;
         ++waited_ms) {
      now_ += 1'000'000;
      fake_.step(now_);
    }
    const PtyCounters& counters = fake_.pty_counters();
    const std::int64_t crossed = counters.bytes_read + counters.bytes_written;
    now_ += (crossed - bytes_seen_) * byte_ns_;
    bytes_seen_ = crossed;
    return now_;
  }

  void sleep_until_ns(hal::MonotonicNs deadline_ns) override {
    if (deadline_ns > now_) {
      now_ = deadline_ns;
    }
    static_cast<void>(now_ns());
  }

 private:
  static constexpr int kLongestWaitMs = 120'000;  // longer than any seek: the driver's own bound decides

  FakeCy545& fake_;
  mutable hal::MonotonicNs now_;
  mutable std::int64_t bytes_seen_ = 0;
  hal::MonotonicNs byte_ns_;
};

}  // namespace stencil::sim::cy545
