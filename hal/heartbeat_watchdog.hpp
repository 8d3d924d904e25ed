// HeartbeatWatchdog: says whether a counter that the other side increments has moved recently.
// Shared by both haptic backends and the simulated device (host side: the device heartbeat; device
// side: the host heartbeat).
#pragma once

#include <cstdint>

#include "hal/clock.hpp"

namespace stencil::hal {

class HeartbeatWatchdog {
 public:
  explicit constexpr HeartbeatWatchdog(MonotonicNs timeout_ns) : timeout_ns_(timeout_ns) {}

  // Records the heartbeat seen at now_ns. Returns false once it has stayed the same for longer than
  // the timeout. The first observation starts the clock. Real-time safe.
  [[nodiscard]] constexpr bool observe(std::uint32_t heartbeat, MonotonicNs now_ns) {
    if (!started_ || heartbeat != last_heartbeat_) {
      started_ = true;
      last_heartbeat_ = heartbeat;
      last_change_ns_ = now_ns;
      return true;
    }
    return !expired(now_ns);
  }

  // True when the heartbeat has not moved for longer than the timeout (false before any observation).
  [[nodiscard]] constexpr bool expired(MonotonicNs now_ns) const {
    return started_ && now_ns - last_change_ns_ > timeout_ns_;
  }

  // Forget the history: the next observation starts the clock again.
  constexpr void restart() { started_ = false; }

  [[nodiscard]] constexpr MonotonicNs timeout_ns() const { return timeout_ns_; }

 private:
  MonotonicNs timeout_ns_;
  MonotonicNs last_change_ns_ = 0;
  std::uint32_t last_heartbeat_ = 0;
  bool started_ = false;
};

}  // namespace stencil::hal
