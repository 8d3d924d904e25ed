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
  // the device was mid-write on every attempt; Rejected / SampleOutOfRange for a pose beyond the range;
  // Fault / HostWatchdogTripped, once, for the first pose that says the device's host watchdog tripped
  // after it was armed for this host (this host stalled past kHostWatchdogMs). Every pose read, even
  // a stale or refused one, moves the arming on (see Arming).
  ReadResult read_sample(MonotonicNs now_ns, HapticSample& out) override;

  // Real-time safe: one seqlock write of the command block, host heartbeat + 1. Until the device is
  // armed, and after a trip until the caller has cleared the fault, enable on goes out as zero force
  // with enable off (Held).
  WriteResult write_command(const HapticCommand& command) override;

  [[nodiscard]] HapticLinkState link_state() const override { return state_; }
  [[nodiscard]] HapticFault latched_fault() const override { return latched_fault_; }
  // Also lets enable on through again after a trip (once the device is armed).
  void clear_fault() override {
    latched_fault_ = HapticFault::None;
    trip_to_clear_ = false;
  }
  [[nodiscard]] HapticCounters counters() const override { return counters_; }

 private:
  // Whether the device drives this host's enable. The window's rule (shared_window_layout.hpp,
  // Heartbeats): a tripped device waits for enable off, then enable on; it may have tripped before
  // this host started (an earlier run's host died), so every host starts Disarmed.
  enum class Arming : std::uint8_t {
    Disarmed,    // no enable off of this arming written yet: whatever the caller asks, enable off goes
    OffWritten,  // an enable off is in the window: the next pose read gives the counter to count from
    Confirming,  // waiting for a pose with the trip bit clear, two or more after that counter
    Armed,       // the device re-armed (or never tripped) on our enable off: the caller's enable goes
  };

  ReadResult fault(HapticFault reason);
  // Moves the arming on from one consistent pose (stale or not). True when a new pose reports a trip
  // after the device was armed: the caller must hear it (the arming starts again).
  [[nodiscard]] bool advance_arming(const PoseWords& pose, bool new_pose);

  SharedWindow* window_;
  HapticRange range_;
  HeartbeatWatchdog device_watchdog_;
  HapticLinkState state_;
  HapticFault latched_fault_ = HapticFault::None;
  HapticCounters counters_{};
  std::uint32_t last_seen_sample_counter_ = 0;
  bool seen_a_sample_ = false;
  std::uint32_t host_heartbeat_ = 0;
  Arming arming_ = Arming::Disarmed;
  std::uint32_t arming_from_counter_ = 0;  // the first pose counter read after the enable off (Confirming)
  bool trip_to_clear_ = false;             // a trip was reported and clear_fault() has not been called since
};

}  // namespace stencil::hal::pio_shared_memory
