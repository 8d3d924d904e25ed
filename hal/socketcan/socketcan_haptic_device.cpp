// The host's side of the haptic CAN exchange: drain, pair and check the device's frames; clamp,
// encode and send the command; watch the device heartbeat.
#include "hal/socketcan/socketcan_haptic_device.hpp"

#include <algorithm>

#include "hal/haptic_range_checks.hpp"

namespace stencil::hal::socketcan {

SocketCanHapticDevice::SocketCanHapticDevice(CanChannel* channel, const HapticRange& range,
                                             MonotonicNs device_watchdog_ns)
    : channel_(channel),
      range_(range),
      assembler_(range),
      device_watchdog_(device_watchdog_ns),
      state_(channel == nullptr ? HapticLinkState::Closed : HapticLinkState::WaitingForDevice) {}

HapticCounters SocketCanHapticDevice::counters() const {
  HapticCounters counters = counters_;
  counters.bad_frames = assembler_.rejections().total();
  counters.samples_out_of_range = assembler_.rejections().of(FrameRejection::OutOfRange);
  return counters;
}

ReadResult SocketCanHapticDevice::read_fault(HapticFault reason) {
  if (latched_fault_ == HapticFault::None) latched_fault_ = reason;
  return {ReadStatus::Fault, reason};
}

WriteResult SocketCanHapticDevice::write_fault(HapticFault reason) {
  if (latched_fault_ == HapticFault::None) latched_fault_ = reason;
  return {WriteStatus::Fault, reason};
}

void SocketCanHapticDevice::take(TransferStatus received, const can_frame& frame, Drained& drained) {
  if (received == TransferStatus::WrongSize) {
    assembler_.count(FrameRejection::WrongSize);
    drained.refused = FrameRejection::WrongSize;
    return;
  }
  if (received != TransferStatus::Done) {
    ++counters_.transport_errors;
    state_ = HapticLinkState::Disconnected;
    drained.fault = HapticFault::TransportError;
    return;
  }
  if (is_error_frame(frame)) {
    ++can_counters_.error_frames;
    const CanBusError error = classify_error_frame(frame);
    if (!stops_the_link(error)) return;  // recovered, or a single bus error: counted only
    if (latched_fault_ == HapticFault::None) bus_error_ = error;
    state_ = HapticLinkState::Disconnected;
    status_since_bus_error_ = false;
    drained.fault = HapticFault::TransportError;
    return;
  }
  const FrameResult result = assembler_.accept(frame);
  if (result.effect == FrameEffect::Completed) drained.new_pose = true;
  if (result.effect == FrameEffect::Status) drained.status = true;
  if (result.effect == FrameEffect::Rejected) drained.refused = result.rejection;
}

void SocketCanHapticDevice::drain_at_start(Drained& drained) {
  first_read_done_ = true;
  // Up to one ordinary read's frames, held back until it is known whether more wait behind them.
  can_frame held[kMaxFramesPerRead];
  TransferStatus held_status[kMaxFramesPerRead];
  int count = 0;
  bool more_waiting = true;
  for (; count < kMaxFramesPerRead; ++count) {
    held_status[count] = channel_->receive(held[count]);
    if (held_status[count] == TransferStatus::WouldBlock) {
      more_waiting = false;
      break;
    }
    if (held_status[count] == TransferStatus::Closed || held_status[count] == TransferStatus::Error) {
      take(held_status[count], held[count], drained);
      return;
    }
  }
  can_frame next{};
  TransferStatus next_status = TransferStatus::WouldBlock;
  if (more_waiting) {
    next_status = channel_->receive(next);
    more_waiting = next_status != TransferStatus::WouldBlock;
  }
  if (!more_waiting) {  // a few milliseconds' frames at most: as any read takes them
    for (int index = 0; index < count && drained.fault == HapticFault::None; ++index) {
      take(held_status[index], held[index], drained);
    }
    return;
  }
  // The link sat unread: a backlog, oldest first. Only its error frames count.
  discarding_backlog_ = true;
  for (int index = 0; index <= count && drained.fault == HapticFault::None; ++index) {
    const TransferStatus status = index < count ? held_status[index] : next_status;
    const can_frame& frame = index < count ? held[index] : next;
    if (status == TransferStatus::Done && is_error_frame(frame)) {
      take(status, frame, drained);
    } else if (status == TransferStatus::Done || status == TransferStatus::WrongSize) {
      ++can_counters_.frames_discarded_at_start;
    } else {
      take(status, frame, drained);
    }
  }
  if (drained.fault == HapticFault::None) discard_backlog(drained);
}

void SocketCanHapticDevice::discard_backlog(Drained& drained) {
  for (int frame_index = 0; frame_index < kMaxFramesDiscardedPerRead; ++frame_index) {
    can_frame frame;
    const TransferStatus received = channel_->receive(frame);
    if (received == TransferStatus::WouldBlock) {
      discarding_backlog_ = false;  // empty: what comes next was sent after the cycle started
      return;
    }
    if (received == TransferStatus::Done && !is_error_frame(frame)) {
      ++can_counters_.frames_discarded_at_start;
      continue;
    }
    if (received == TransferStatus::WrongSize) {
      ++can_counters_.frames_discarded_at_start;
      continue;
    }
    take(received, frame, drained);
    if (drained.fault != HapticFault::None) return;
  }
  // The bound: the rest waits for the next read, which carries on discarding.
}

ReadResult SocketCanHapticDevice::read_sample(MonotonicNs now_ns, HapticSample& out) {
  if (channel_ == nullptr) return read_fault(HapticFault::NotOpen);

  Drained drained;
  if (discarding_backlog_) {
    discard_backlog(drained);
  } else if (!first_read_done_) {
    drain_at_start(drained);
  } else {
    for (int frame_index = 0; frame_index < kMaxFramesPerRead && drained.fault == HapticFault::None; ++frame_index) {
      can_frame frame;
      const TransferStatus received = channel_->receive(frame);
      if (received == TransferStatus::WouldBlock) break;
      take(received, frame, drained);
    }
  }
  if (drained.fault != HapticFault::None) return read_fault(drained.fault);

  // The device heartbeat comes with the Status frame; none yet counts as a heartbeat that never moved.
  const std::uint32_t heartbeat = assembler_.has_status() ? assembler_.latest_status().device_heartbeat : 0U;
  if (!device_watchdog_.observe(heartbeat, now_ns)) {
    state_ = HapticLinkState::Disconnected;
    return read_fault(HapticFault::DeviceHeartbeatLost);
  }
  if (drained.status) status_since_bus_error_ = true;
  if (assembler_.has_status() && status_since_bus_error_) state_ = HapticLinkState::Connected;

  if (!drained.new_pose) {
    if (drained.refused != FrameRejection::None) {
      return {ReadStatus::Rejected, drained.refused == FrameRejection::OutOfRange ? HapticFault::SampleOutOfRange
                                                                                  : HapticFault::BadFrame};
    }
    ++counters_.stale_reads;
    return {ReadStatus::Stale, HapticFault::None};
  }

  const PoseWire& pose = assembler_.latest_pose();
  // Extend the 8-bit wire counter: frames arrive in order, so the difference mod 256 is the advance.
  if (seen_a_pose_) {
    sample_counter_ += static_cast<std::uint8_t>(pose.counter - static_cast<std::uint8_t>(sample_counter_));
  } else {
    sample_counter_ = pose.counter;
    seen_a_pose_ = true;
  }
  HapticSample sample;
  for (int axis = 0; axis < 3; ++axis) sample.position_mm[axis] = pose.position_um[axis] * 1e-3;
  for (int angle = 0; angle < 2; ++angle) sample.angles_rad[angle] = pose.angles_100urad[angle] * kAngleRadPerUnit;
  sample.sample_counter = sample_counter_;
  sample.status_bits = assembler_.latest_status().status_bits;
  sample.device_heartbeat = heartbeat;
  out = sample;
  ++counters_.samples_accepted;
  return {ReadStatus::Fresh, HapticFault::None};
}

WriteResult SocketCanHapticDevice::write_command(const HapticCommand& command) {
  if (channel_ == nullptr) return write_fault(HapticFault::NotOpen);
  // Never more than the device accepts, whatever the range says.
  const double force_limit_n = std::min(range_.force_limit_n, kForceLimitMn * 1e-3);
  const double torque_limit_nmm = std::min(range_.torque_limit_nmm, kTorqueLimitUnits * kTorqueNmmPerUnit);
  const ClampedCommand clamped =
      clamp_command(command, force_limit_n, torque_limit_nmm);

  CommandWire wire{};
  wire.counter = static_cast<std::uint8_t>(command.cycle_counter & 0xFFU);
  for (int axis = 0; axis < 3; ++axis) {
    wire.force_mn[axis] = static_cast<std::int16_t>(to_units_toward_zero(clamped.force_n[axis], 1e3));
  }
  for (int axis = 0; axis < 2; ++axis) {
    wire.torque_10mnmm[axis] = static_cast<std::int16_t>(
        to_units_toward_zero(clamped.torque_nmm[axis], 1.0 / kTorqueNmmPerUnit));
  }
  wire.enable = clamped.finite && command.enable;
  wire.host_heartbeat = ++host_heartbeat_;

  can_frame force_frame;
  can_frame torque_frame;
  encode_command(wire, force_frame, torque_frame);
  for (const can_frame* frame : {&force_frame, &torque_frame}) {
    const TransferStatus sent = channel_->send(*frame);
    if (sent == TransferStatus::Done) continue;
    ++counters_.transport_errors;
    return write_fault(sent == TransferStatus::WouldBlock ? HapticFault::TransportFull : HapticFault::TransportError);
  }

  return write_outcome(clamped, counters_);
}

}  // namespace stencil::hal::socketcan
