// SocketCanHapticDevice: the host's side of the haptic CAN exchange (can_frame_layout.hpp) as a
// hal::HapticDevice, over any CanChannel. Real-time core: the codec and bounded, non-blocking frame
// moves only.
#pragma once

#include <cstdint>

#include "hal/haptic_device.hpp"
#include "hal/heartbeat_watchdog.hpp"
#include "hal/socketcan/can_channel.hpp"
#include "hal/socketcan/can_codec.hpp"

namespace stencil::hal::socketcan {

inline constexpr MonotonicNs kDefaultDeviceWatchdogNs = 50'000'000;  // 50 missed status frames at 1 kHz
// Frames drained per read: 3 per device cycle, so about 10 ms of backlog; more waits for the next read.
inline constexpr int kMaxFramesPerRead = 32;

class SocketCanHapticDevice final : public HapticDevice {
 public:
  // `channel` may be null (Closed). It must outlive this object. Init-time.
  SocketCanHapticDevice(CanChannel* channel, const HapticRange& range,
                        MonotonicNs device_watchdog_ns = kDefaultDeviceWatchdogNs);

  // Drains at most kMaxFramesPerRead waiting frames (never waits), pairs the pose halves, and gives
  // the newest complete pose. Fresh when a new pose arrived; Rejected / BadFrame or SampleOutOfRange
  // when frames arrived but none made a pose and some were refused; Stale when nothing new came; Fault
  // on a closed or failing channel or a device heartbeat (Status frame) frozen past the watchdog time.
  ReadResult read_sample(MonotonicNs now_ns, HapticSample& out) override;

  // Sends the Force and Torque frames of one command (never waits). Fault / TransportFull when the
  // channel's queue is full (the command is dropped and counted), TransportError when it fails.
  WriteResult write_command(const HapticCommand& command) override;

  [[nodiscard]] HapticLinkState link_state() const override { return state_; }
  [[nodiscard]] HapticFault latched_fault() const override { return latched_fault_; }
  void clear_fault() override { latched_fault_ = HapticFault::None; }
  [[nodiscard]] HapticCounters counters() const override;

  // Refused frames by kind (HapticCounters::bad_frames is their total).
  [[nodiscard]] const RejectionCounters& rejections() const { return assembler_.rejections(); }

 private:
  ReadResult read_fault(HapticFault reason);
  WriteResult write_fault(HapticFault reason);

  CanChannel* channel_;
  HapticRange range_;
  HostFrameAssembler assembler_;
  HeartbeatWatchdog device_watchdog_;
  HapticLinkState state_;
  HapticFault latched_fault_ = HapticFault::None;
  HapticCounters counters_{};
  std::uint32_t sample_counter_ = 0;  // the 8-bit wire counter, extended
  bool seen_a_pose_ = false;
  std::uint16_t host_heartbeat_ = 0;
};

}  // namespace stencil::hal::socketcan
