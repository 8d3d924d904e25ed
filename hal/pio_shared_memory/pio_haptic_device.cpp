// The host's side of the PIO shared memory window: seqlock read of the pose, seqlock write of the
// command, the device heartbeat watchdog, arming the device's host watchdog, and the range rules.
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
  const bool new_pose = !seen_a_sample_ || words.sample_counter != last_seen_sample_counter_;
  if (advance_arming(words, new_pose)) {
    seen_a_sample_ = true;
    last_seen_sample_counter_ = words.sample_counter;  // this pose is given once, as the fault
    trip_to_clear_ = true;
    return fault(HapticFault::HostWatchdogTripped);
  }
  if (!new_pose) {
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

// The device (shared_window_layout.hpp, Heartbeats) zeroes its force when the host heartbeat freezes
// for kHostWatchdogMs and then drives nothing until it has read enable off and then enable on. It may
// have tripped before this host started (the last run's host died), and nothing in the window says
// which command it has read, so the backend arms it itself before passing the caller's enable on:
//  1. it writes enable off (Disarmed -> OffWritten);
//  2. the first pose it reads after that gives a counter X (-> Confirming). The device may have
//     written X, and X + 1, before it read the enable off, but it writes X + 2 only after reading a
//     command that came after X was read: ours, all enable off until armed;
//  3. a pose X + 2 or later with kHostWatchdogTripped clear means the device is armed (-> Armed): it
//     re-armed on our enable off, or never tripped.
// A pose with the bit clear read right after the enable off would not do: it may predate the device's
// read of it and come from a device that trips a moment later (the last host died 20 ms ago).
// Holding the first cycles at zero costs nothing: arming takes three or four device cycles (4 ms),
// and after a start the controller ramps force in over 0.5 s, so at most ~1 % of a force is held
// back for those milliseconds; zero force is what the device drives whenever it is unsure anyway.
bool PioHapticDevice::advance_arming(const PoseWords& pose, bool new_pose) {
  const bool tripped = (pose.status_bits & haptic_status::kHostWatchdogTripped) != 0U;
  switch (arming_) {
    case Arming::Disarmed:
      return false;
    case Arming::OffWritten:
      arming_from_counter_ = pose.sample_counter;
      arming_ = Arming::Confirming;
      return false;
    case Arming::Confirming:
      // Unsigned difference: right across the counter's wrap.
      if (!tripped && pose.sample_counter - arming_from_counter_ >= 2U) arming_ = Arming::Armed;
      return false;
    case Arming::Armed:
      if (!tripped || !new_pose) return false;
      arming_ = Arming::Disarmed;  // it waits for enable off again
      return true;
  }
  return false;
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

  // Enable on waits for the device to be armed, and after a trip also for the caller to clear the
  // fault (the controller's safe state sends enable off anyway; a caller that ignores the fault, or
  // whose latch held an earlier one, gets no force either).
  const bool enable_asked = clamped.finite && command.enable;
  const bool held = enable_asked && (arming_ != Arming::Armed || trip_to_clear_);

  CommandWords words{};  // held: zero force and torque, enable off
  words.cycle_counter = command.cycle_counter;
  if (!held) {
    for (int axis = 0; axis < 3; ++axis) words.force_mn[axis] = to_units_toward_zero(clamped.force_n[axis], 1e3);
    for (int axis = 0; axis < 2; ++axis) {
      words.torque_mnmm[axis] = to_units_toward_zero(clamped.torque_nmm[axis], 1e3);
    }
  }
  words.flags = enable_asked && !held ? kCommandEnableBit : 0U;
  words.host_heartbeat = ++host_heartbeat_;
  seqlock_write(window_->command, words);
  if (words.flags == 0U && arming_ == Arming::Disarmed) arming_ = Arming::OffWritten;

  const WriteResult outcome = write_outcome(clamped, counters_);  // a clamp is counted even when held
  if (held) return {WriteStatus::Held, HapticFault::None};
  return outcome;
}

}  // namespace stencil::hal::pio_shared_memory
