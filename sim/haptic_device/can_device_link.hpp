// CanDeviceLink: the simulated device's end of the haptic CAN exchange (pose, status, command frames).
#pragma once

#include <cstdint>

#include "hal/socketcan/can_channel.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "sim/haptic_device/device_side_link.hpp"

namespace stencil::sim {

class CanDeviceLink final : public DeviceSideLink {
 public:
  // The channel must outlive this object: one end of a socket pair (every frame arrives at once), the
  // device() node of a SimulatedCanBus (frames take wire time, queues are bounded), or a CAN_RAW socket.
  explicit CanDeviceLink(hal::socketcan::CanChannel& channel) : channel_(channel) {}

  // Sends PoseA, PoseB and Status (a full queue drops frames, counted).
  void publish(const hal::HapticSample& sample) override;
  // Drains at most 64 waiting frames and keeps the newest complete command.
  [[nodiscard]] CommandPoll poll(DeviceCommand& out) override;

  // A babbling device (fault injection): this many publishes send bad pose frames instead of good
  // ones (PoseA with DLC 5, then a PoseA and a PoseB whose counters disagree); the status frame, and
  // with it the heartbeat, still goes, and commands are still taken.
  void babble(int publishes) { babbling_ = publishes; }

  [[nodiscard]] const hal::socketcan::RejectionCounters& rejections() const { return assembler_.rejections(); }
  [[nodiscard]] std::uint64_t frames_dropped() const { return frames_dropped_; }

 private:
  hal::socketcan::CanChannel& channel_;
  hal::socketcan::DeviceFrameAssembler assembler_;
  std::uint64_t frames_dropped_ = 0;
  int babbling_ = 0;
};

}  // namespace stencil::sim
