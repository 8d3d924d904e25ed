// The simulated device's end of the haptic CAN exchange.
#include "sim/haptic_device/can_device_link.hpp"

#include <initializer_list>

#include "sim/haptic_device/wire_units.hpp"

namespace stencil::sim {

namespace can = hal::socketcan;

void CanDeviceLink::publish(const hal::HapticSample& sample) {
  can::PoseWire pose{};
  pose.counter = static_cast<std::uint8_t>(sample.sample_counter & 0xFFU);
  for (int axis = 0; axis < 3; ++axis) {
    pose.position_um[axis] = saturated_units(sample.position_mm[axis], 1e3, can::kInt24Min, can::kInt24Max);
  }
  for (int angle = 0; angle < 2; ++angle) {
    pose.angles_100urad[angle] = saturated_units<std::int16_t>(sample.angles_rad[angle], 1.0 / can::kAngleRadPerUnit);
  }
  can::StatusWire status{pose.counter, static_cast<std::uint16_t>(sample.status_bits & 0xFFFFU), sample.device_heartbeat};
  can_frame frames[3];
  if (!can::encode_pose(pose, frames[0], frames[1])) return;  // cannot happen: saturated to int24 above
  can::encode_status(status, frames[2]);
  if (babbling_ > 0) {
    --babbling_;
    can_frame short_a = frames[0];
    short_a.can_dlc = 5;
    can_frame other_b = frames[1];
    other_b.data[0] = static_cast<std::uint8_t>(other_b.data[0] + 1);
    for (const can_frame& frame : {short_a, frames[0], other_b, frames[2]}) {
      if (channel_.send(frame) != can::TransferStatus::Done) ++frames_dropped_;
    }
    return;
  }
  for (const can_frame& frame : frames) {
    if (channel_.send(frame) != can::TransferStatus::Done) ++frames_dropped_;
  }
}

CommandPoll CanDeviceLink::poll(DeviceCommand& out) {
  bool completed = false;
  bool refused = false;
  for (int frame_index = 0; frame_index < 64; ++frame_index) {
    can_frame frame;
    const can::TransferStatus received = channel_.receive(frame);
    if (received == can::TransferStatus::WrongSize) {
      assembler_.count(can::FrameRejection::WrongSize);
      refused = true;
      continue;
    }
    if (received != can::TransferStatus::Done) break;
    const can::FrameResult result = assembler_.accept(frame);
    if (result.effect == can::FrameEffect::Completed) completed = true;
    if (result.effect == can::FrameEffect::Rejected) refused = true;
  }
  if (!completed) return refused ? CommandPoll::Refused : CommandPoll::None;
  const can::CommandWire& command = assembler_.latest_command();
  for (int axis = 0; axis < 3; ++axis) out.force_n[axis] = command.force_mn[axis] * 1e-3;
  for (int axis = 0; axis < 2; ++axis) out.torque_nmm[axis] = command.torque_10mnmm[axis] * can::kTorqueNmmPerUnit;
  out.cycle_counter = command.counter;
  out.host_heartbeat = command.host_heartbeat;
  out.enable = command.enable;
  return CommandPoll::New;
}

}  // namespace stencil::sim
