// Encoding and decoding of the haptic CAN frames; pairing of halves; refusal of bad frames.
#include "hal/socketcan/can_codec.hpp"

#include <cmath>

namespace stencil::hal::socketcan {

namespace {

void start_frame(can_frame& frame, canid_t id, std::uint8_t counter) {
  frame = can_frame{};
  frame.can_id = id;
  frame.len = kFrameBytes;
  frame.data[0] = counter;
}

void put_u16(std::uint8_t* bytes, std::uint16_t value) {
  bytes[0] = static_cast<std::uint8_t>(value & 0xFFU);
  bytes[1] = static_cast<std::uint8_t>(value >> 8U);
}
void put_i16(std::uint8_t* bytes, std::int16_t value) { put_u16(bytes, static_cast<std::uint16_t>(value)); }
void put_i24(std::uint8_t* bytes, std::int32_t value) {
  const auto bits = static_cast<std::uint32_t>(value);
  bytes[0] = static_cast<std::uint8_t>(bits & 0xFFU);
  bytes[1] = static_cast<std::uint8_t>((bits >> 8U) & 0xFFU);
  bytes[2] = static_cast<std::uint8_t>((bits >> 16U) & 0xFFU);
}
void put_u32(std::uint8_t* bytes, std::uint32_t value) {
  for (unsigned byte = 0; byte < 4; ++byte) bytes[byte] = static_cast<std::uint8_t>((value >> (8U * byte)) & 0xFFU);
}

std::uint16_t get_u16(const std::uint8_t* bytes) {
  return static_cast<std::uint16_t>(bytes[0] | (bytes[1] << 8U));
}
std::int16_t get_i16(const std::uint8_t* bytes) { return static_cast<std::int16_t>(get_u16(bytes)); }
std::int32_t get_i24(const std::uint8_t* bytes) {
  const std::uint32_t bits = bytes[0] | (std::uint32_t{bytes[1]} << 8U) | (std::uint32_t{bytes[2]} << 16U);
  // Sign-extend from bit 23.
  return static_cast<std::int32_t>(bits ^ 0x800000U) - 0x800000;
}
std::uint32_t get_u32(const std::uint8_t* bytes) {
  return bytes[0] | (std::uint32_t{bytes[1]} << 8U) | (std::uint32_t{bytes[2]} << 16U) |
         (std::uint32_t{bytes[3]} << 24U);
}

bool fits_int24(std::int32_t value) { return value >= kInt24Min && value <= kInt24Max; }

// A standard data frame with one of our IDs: anything with the EFF, RTR or ERR flag is not.
bool is_standard_data_frame(const can_frame& frame) {
  return (frame.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) == 0U;
}

std::int64_t squared(std::int32_t value) { return std::int64_t{value} * value; }

}  // namespace

bool encode_pose(const PoseWire& pose, can_frame& pose_a, can_frame& pose_b) {
  for (const std::int32_t position : pose.position_um) {
    if (!fits_int24(position)) return false;
  }
  start_frame(pose_a, kPoseAId, pose.counter);
  put_i24(&pose_a.data[1], pose.position_um[0]);
  put_i24(&pose_a.data[4], pose.position_um[1]);
  start_frame(pose_b, kPoseBId, pose.counter);
  put_i24(&pose_b.data[1], pose.position_um[2]);
  put_i16(&pose_b.data[4], pose.angles_100urad[0]);
  put_i16(&pose_b.data[6], pose.angles_100urad[1]);
  return true;
}

void encode_status(const StatusWire& status, can_frame& frame) {
  start_frame(frame, kStatusId, status.counter);
  put_u16(&frame.data[1], status.status_bits);
  put_u32(&frame.data[3], status.device_heartbeat);
}

void encode_command(const CommandWire& command, can_frame& force, can_frame& torque) {
  start_frame(force, kForceId, command.counter);
  for (int axis = 0; axis < 3; ++axis) put_i16(&force.data[1 + 2 * axis], command.force_mn[axis]);
  force.data[7] = command.enable ? kEnableFlag : 0U;
  start_frame(torque, kTorqueId, command.counter);
  put_i16(&torque.data[1], command.torque_10mnmm[0]);
  put_i16(&torque.data[3], command.torque_10mnmm[1]);
  put_u16(&torque.data[5], command.host_heartbeat);
}

FrameResult HostFrameAssembler::reject(FrameRejection kind) {
  rejections_.count(kind);
  return {FrameEffect::Rejected, kind};
}

FrameResult HostFrameAssembler::accept(const can_frame& frame) {
  if (!is_standard_data_frame(frame)) return reject(FrameRejection::UnknownId);
  const canid_t id = frame.can_id & CAN_SFF_MASK;
  if (id != kPoseAId && id != kPoseBId && id != kStatusId) return reject(FrameRejection::UnknownId);
  if (frame.len != kFrameBytes) return reject(FrameRejection::WrongDlc);
  const std::uint8_t counter = frame.data[0];

  if (id == kStatusId) {
    if (frame.data[7] != 0U) return reject(FrameRejection::ReservedNotZero);
    latest_status_ = {counter, get_u16(&frame.data[1]), get_u32(&frame.data[3])};
    has_status_ = true;
    return {FrameEffect::Status, FrameRejection::None};
  }

  if (id == kPoseAId) {
    if (frame.data[7] != 0U) return reject(FrameRejection::ReservedNotZero);
    // A first half still waiting lost its partner: refuse it (counted), keep the new one.
    if (half_waiting_) rejections_.count(FrameRejection::UnpairedHalf);
    waiting_ = PoseWire{counter, {get_i24(&frame.data[1]), get_i24(&frame.data[4]), 0}, {0, 0}};
    half_waiting_ = true;
    return {FrameEffect::HalfHeld, FrameRejection::None};
  }

  // PoseB: completes the waiting PoseA, or is refused with it.
  if (!half_waiting_) return reject(FrameRejection::UnpairedHalf);
  half_waiting_ = false;
  if (counter != waiting_.counter) return reject(FrameRejection::HalvesDisagree);
  PoseWire pose = waiting_;
  pose.position_um[2] = get_i24(&frame.data[1]);
  pose.angles_100urad[0] = get_i16(&frame.data[4]);
  pose.angles_100urad[1] = get_i16(&frame.data[6]);
  for (int axis = 0; axis < 3; ++axis) {
    if (!(std::fabs(pose.position_um[axis] * 1e-3 - range_.position_centre_mm[axis]) <= range_.position_limit_mm[axis])) {
      return reject(FrameRejection::OutOfRange);
    }
  }
  for (const std::int16_t angle : pose.angles_100urad) {
    if (!(std::fabs(angle * kAngleRadPerUnit) <= range_.angle_limit_rad)) return reject(FrameRejection::OutOfRange);
  }
  latest_pose_ = pose;
  return {FrameEffect::Completed, FrameRejection::None};
}

FrameResult DeviceFrameAssembler::reject(FrameRejection kind) {
  rejections_.count(kind);
  return {FrameEffect::Rejected, kind};
}

FrameResult DeviceFrameAssembler::accept(const can_frame& frame) {
  if (!is_standard_data_frame(frame)) return reject(FrameRejection::UnknownId);
  const canid_t id = frame.can_id & CAN_SFF_MASK;
  if (id != kForceId && id != kTorqueId) return reject(FrameRejection::UnknownId);
  if (frame.len != kFrameBytes) return reject(FrameRejection::WrongDlc);
  const std::uint8_t counter = frame.data[0];

  if (id == kForceId) {
    if ((frame.data[7] & ~kEnableFlag) != 0U) return reject(FrameRejection::ReservedNotZero);
    if (half_waiting_) rejections_.count(FrameRejection::UnpairedHalf);
    waiting_ = CommandWire{counter,
                           {get_i16(&frame.data[1]), get_i16(&frame.data[3]), get_i16(&frame.data[5])},
                           {0, 0},
                           0,
                           (frame.data[7] & kEnableFlag) != 0U};
    half_waiting_ = true;
    return {FrameEffect::HalfHeld, FrameRejection::None};
  }

  // Torque: completes the waiting Force, or is refused with it.
  if (!half_waiting_) return reject(FrameRejection::UnpairedHalf);
  half_waiting_ = false;
  if (frame.data[7] != 0U) return reject(FrameRejection::ReservedNotZero);
  if (counter != waiting_.counter) return reject(FrameRejection::HalvesDisagree);
  CommandWire command = waiting_;
  command.torque_10mnmm[0] = get_i16(&frame.data[1]);
  command.torque_10mnmm[1] = get_i16(&frame.data[3]);
  command.host_heartbeat = get_u16(&frame.data[5]);
  const std::int64_t force_squared =
      squared(command.force_mn[0]) + squared(command.force_mn[1]) + squared(command.force_mn[2]);
  const std::int64_t torque_squared = squared(command.torque_10mnmm[0]) + squared(command.torque_10mnmm[1]);
  if (force_squared > squared(kForceLimitMn) || torque_squared > squared(kTorqueLimitUnits)) {
    return reject(FrameRejection::OutOfRange);
  }
  latest_command_ = command;
  return {FrameEffect::Completed, FrameRejection::None};
}

}  // namespace stencil::hal::socketcan
