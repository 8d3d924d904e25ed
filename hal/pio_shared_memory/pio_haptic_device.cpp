// The host's side of the PIO shared memory window: seqlock read of the pose, seqlock write of the
// command, the device heartbeat watchdog and the range rules.
#include "hal/pio_shared_memory/pio_haptic_device.hpp"

#include <algorithm>

#include "hal/haptic_range_checks.hpp"
#include "hal/pio_shared_memory/seqlock.hpp"

namespace stencil::hal::pio_shared_memory {

PioHapticDevice::PioHapticDevice(SharedWindow* window, const HapticRange& range, MonotonicNs device_watchdog_ns)
    : window_(window),
      range_(range),
      device_watchdog_(device_watchdog_ns),
      state_(window == nullptr ? HapticLinkState::Closed : HapticLinkState::WaitingForDevice) {
  // A restarted host continues the heartbeat it left in the window, so the device sees it move.
  if (window_ != nullptr) host_heartbeat_ = load_word(window_->command.host_heartbeat);
}

ReadResult PioHapticDevice::fault(HapticFault reason) {
  if (latched_fault_ == HapticFault::None) latched_fault_ = reason;
  return {ReadStatus::Fault, reason};
}

ReadResult PioHapticDevice::read_sample(MonotonicNs now_ns, HapticSample& out) {
  if (window_ == nullptr) return fault(HapticFault::NotOpen);

  PoseWords words{};
  const SeqlockRead read = seqlock_read(window_->pose, words);
  counters_.torn_read_retries += static_cast<std::uint64_t>(read.retries);
  if (!read.consistent) {
    // A writer stuck mid-write also stops its heartbeat: past the watchdog time it is a disconnect.
    if (device_watchdog_.expired(now_ns)) {
      state_ = HapticLinkState::Disconnected;
      return fault(HapticFault::DeviceHeartbeatLost);
    }
    ++counters_.busy_reads;
    return {ReadStatus::Rejected, HapticFault::SampleBusy};
  }

  if (!device_watchdog_.observe(words.device_heartbeat, now_ns)) {
    state_ = HapticLinkState::Disconnected;
    return fault(HapticFault::DeviceHeartbeatLost);
  }
  if (read.sequence == 0U) {  // the device has not written a pose yet
    ++counters_.stale_reads;
    return {ReadStatus::Stale, HapticFault::None};
  }
  state_ = HapticLinkState::Connected;
  if (seen_a_sample_ && words.sample_counter == last_seen_sample_counter_) {
    ++counters_.stale_reads;
    return {ReadStatus::Stale, HapticFault::None};
  }
  seen_a_sample_ = true;
  last_seen_sample_counter_ = words.sample_counter;

  HapticSample sample;
  for (int axis = 0; axis < 3; ++axis) sample.position_mm[axis] = words.position_um[axis] * 1e-3;
  for (int angle = 0; angle < 2; ++angle) sample.angles_rad[angle] = words.angles_urad[angle] * 1e-6;
  sample.sample_counter = words.sample_counter;
  sample.status_bits = words.status_bits;
  sample.device_heartbeat = words.device_heartbeat;
  if (!sample_in_range(sample, range_)) {
    ++counters_.samples_out_of_range;
    return {ReadStatus::Rejected, HapticFault::SampleOutOfRange};
  }
  out = sample;
  ++counters_.samples_accepted;
  return {ReadStatus::Fresh, HapticFault::None};
}

WriteResult PioHapticDevice::write_command(const HapticCommand& command) {
  if (window_ == nullptr) {
    if (latched_fault_ == HapticFault::None) latched_fault_ = HapticFault::NotOpen;
    return {WriteStatus::Fault, HapticFault::NotOpen};
  }
  // Never more than the device itself accepts, whatever the range says.
  const double force_limit_n = std::min(range_.force_limit_n, kForceLimitMn * 1e-3);
  const double torque_limit_nmm = std::min(range_.torque_limit_nmm, kTorqueLimitMnmm * 1e-3);
  const ClampedCommand clamped = clamp_command(command, force_limit_n, torque_limit_nmm);

  CommandWords words{};
  words.cycle_counter = command.cycle_counter;
  for (int axis = 0; axis < 3; ++axis) words.force_mn[axis] = to_units_toward_zero(clamped.force_n[axis], 1e3);
  for (int axis = 0; axis < 2; ++axis) {
    words.torque_mnmm[axis] = to_units_toward_zero(clamped.torque_nmm[axis], 1e3);
  }
  words.flags = clamped.finite && command.enable ? kCommandEnableBit : 0U;
  words.host_heartbeat = ++host_heartbeat_;
  seqlock_write(window_->command, words);

  return write_outcome(clamped, counters_);
}

}  // namespace stencil::hal::pio_shared_memory
