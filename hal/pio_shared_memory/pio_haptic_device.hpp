// PioHapticDevice: the host's side of the PIO card's shared memory window as a hal::HapticDevice.
// Real-time core: it only loads and stores words of a window that init-time code has mapped
// (shared_window_mapping.hpp).
#pragma once

#include <cstdint>

#include "hal/haptic_device.hpp"
#include "hal/heartbeat_watchdog.hpp"
#include "hal/pio_shared_memory/shared_window_layout.hpp"

namespace stencil::hal::pio_shared_memory {

inline constexpr MonotonicNs kDefaultDeviceWatchdogNs = 50'000'000;  // 50 missed samples at 1 kHz

class PioHapticDevice final : public HapticDevice {
 public:
  // `window` may be null (Closed: every call reports NotOpen). The window must outlive this object.
  // Init-time (no allocation either, but it reads the window once to continue its host heartbeat).
  PioHapticDevice(SharedWindow* window, const HapticRange& range,
                  MonotonicNs device_watchdog_ns = kDefaultDeviceWatchdogNs);

  // Real-time safe: a bounded seqlock read (kSeqlockAttempts), no wait. Rejected / SampleBusy when
  // the device was mid-write on every attempt; Rejected / SampleOutOfRange for a pose beyond the range.
  ReadResult read_sample(MonotonicNs now_ns, HapticSample& out) override;

  // Real-time safe: one seqlock write of the command block, host heartbeat + 1.
  WriteResult write_command(const HapticCommand& command) override;

  [[nodiscard]] HapticLinkState link_state() const override { return state_; }
  [[nodiscard]] HapticFault latched_fault() const override { return latched_fault_; }
  void clear_fault() override { latched_fault_ = HapticFault::None; }
  [[nodiscard]] HapticCounters counters() const override { return counters_; }

 private:
  ReadResult fault(HapticFault reason);

  SharedWindow* window_;
  HapticRange range_;
  HeartbeatWatchdog device_watchdog_;
  HapticLinkState state_;
  HapticFault latched_fault_ = HapticFault::None;
  HapticCounters counters_{};
  std::uint32_t last_seen_sample_counter_ = 0;
  bool seen_a_sample_ = false;
  std::uint32_t host_heartbeat_ = 0;
};

}  // namespace stencil::hal::pio_shared_memory
