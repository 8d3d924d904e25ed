// The pure, allocation-free codec of the haptic CAN frames (can_frame_layout.hpp): encoders for both
// sides, and the assemblers that pair halves and refuse (and count) bad frames. Real-time core.
#pragma once

#include <linux/can.h>

#include <cstdint>

#include "hal/haptic_device.hpp"
#include "hal/socketcan/can_frame_layout.hpp"

namespace stencil::hal::socketcan {

enum class FrameRejection : std::uint8_t {
  None,
  WrongDlc,         // DLC is not 8
  UnknownId,        // not an ID this side receives, or an extended-ID / remote frame
  OutOfRange,       // a value beyond the range (pose at the host, force or torque at the device)
  ReservedNotZero,  // a reserved byte or flag bit is set
  HalvesDisagree,   // the second half's counter differs from the waiting first half's
  UnpairedHalf,     // a second half with no first half waiting, or a first half replaced unpaired
  WrongSize,        // the transport delivered a message that is not one can_frame (counted there)
};
inline constexpr int kFrameRejectionKinds = 8;

struct RejectionCounters {
  std::uint64_t by_kind[kFrameRejectionKinds];  // indexed by FrameRejection; [None] stays zero

  void count(FrameRejection kind) { ++by_kind[static_cast<int>(kind)]; }
  [[nodiscard]] std::uint64_t of(FrameRejection kind) const { return by_kind[static_cast<int>(kind)]; }
  [[nodiscard]] std::uint64_t total() const {
    std::uint64_t sum = 0;
    for (const std::uint64_t count : by_kind) sum += count;
    return sum;
  }
};

// Encoders. False (frames unusable) when a position does not fit in int24.
[[nodiscard]] bool encode_pose(const PoseWire& pose, can_frame& pose_a, can_frame& pose_b);
void encode_status(const StatusWire& status, can_frame& frame);
void encode_command(const CommandWire& command, can_frame& force, can_frame& torque);

// What one frame did to an assembler.
enum class FrameEffect : std::uint8_t {
  HalfHeld,   // a first half, waiting for its partner
  Completed,  // a pose (host) or command (device) is complete: take it
  Status,     // a status frame was accepted (host)
  Rejected,   // refused and counted; nothing was applied
};

struct [[nodiscard]] FrameResult {
  FrameEffect effect;
  FrameRejection rejection;  // None unless Rejected
};

// The host's side: device frames in, poses and status out. The range refuses poses beyond the
// device's reach (never applied).
class HostFrameAssembler {
 public:
  explicit HostFrameAssembler(const HapticRange& range) : range_(range) {}

  FrameResult accept(const can_frame& frame);

  [[nodiscard]] const PoseWire& latest_pose() const { return latest_pose_; }  // after Completed
  [[nodiscard]] const StatusWire& latest_status() const { return latest_status_; }
  [[nodiscard]] bool has_status() const { return has_status_; }
  [[nodiscard]] const RejectionCounters& rejections() const { return rejections_; }
  void count(FrameRejection kind) { rejections_.count(kind); }

 private:
  FrameResult reject(FrameRejection kind);

  HapticRange range_;
  PoseWire waiting_{};
  bool half_waiting_ = false;
  PoseWire latest_pose_{};
  StatusWire latest_status_{};
  bool has_status_ = false;
  RejectionCounters rejections_{};
};

// The device's side: host frames in, commands out (what the real controller and the simulated device
// do). Commands beyond the device's limits are refused.
class DeviceFrameAssembler {
 public:
  FrameResult accept(const can_frame& frame);

  [[nodiscard]] const CommandWire& latest_command() const { return latest_command_; }  // after Completed
  [[nodiscard]] const RejectionCounters& rejections() const { return rejections_; }
  void count(FrameRejection kind) { rejections_.count(kind); }

 private:
  FrameResult reject(FrameRejection kind);

  CommandWire waiting_{};
  bool half_waiting_ = false;
  CommandWire latest_command_{};
  RejectionCounters rejections_{};
};

}  // namespace stencil::hal::socketcan
