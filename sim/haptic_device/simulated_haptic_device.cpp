// The simulated device: poses out, commands in, and the device-side host-heartbeat watchdog.
#include "sim/haptic_device/simulated_haptic_device.hpp"

#include <utility>
#include <vector>

namespace stencil::sim {

SimulatedHapticDevice::SimulatedHapticDevice(DeviceSideLink& link, PoseSource source,
                                             hal::MonotonicNs host_watchdog_ns)
    : link_(link), source_(std::move(source)), host_watchdog_(host_watchdog_ns) {}

void SimulatedHapticDevice::set_frozen(bool frozen) {
  const std::lock_guard lock(mutex_);
  frozen_ = frozen;
}

void SimulatedHapticDevice::set_device_fault(bool fault) {
  const std::lock_guard lock(mutex_);
  device_fault_ = fault;
}

DeviceOutput SimulatedHapticDevice::output() const {
  const std::lock_guard lock(mutex_);
  return output_;
}

void SimulatedHapticDevice::zero_output() {
  for (double& force : output_.force_n) force = 0.0;
  for (double& torque : output_.torque_nmm) torque = 0.0;
  output_.force_applied = false;
}

void SimulatedHapticDevice::step(hal::MonotonicNs now_ns) {
  const std::lock_guard lock(mutex_);
  if (frozen_) return;

  DeviceCommand received{};
  switch (link_.poll(received)) {
    case CommandPoll::New:
      command_ = received;
      have_command_ = true;
      output_.last_command_refused = false;
      output_.last_cycle_counter = received.cycle_counter;
      ++output_.commands_accepted;
      break;
    case CommandPoll::Refused:
      output_.last_command_refused = true;
      ++output_.commands_refused;
      break;
    case CommandPoll::None: break;
  }

  // The watchdog starts with the host's first command: before it there is no force to take away.
  if (have_command_ && !host_watchdog_.observe(command_.host_heartbeat, now_ns) && !output_.watchdog_tripped) {
    output_.watchdog_tripped = true;
    ++output_.watchdog_trips;
  }
  // Re-arming: the host, beating again, first sends enable off; its next enable on drives force (the
  // window's contract, hal/pio_shared_memory/shared_window_layout.hpp, Heartbeats; the same on CAN).
  // The trip is this device's state, not the host's: a host that ends and a new one that opens the
  // same window or bus find it still tripped, and the new one must re-arm it like any other.
  if (output_.watchdog_tripped && !host_watchdog_.expired(now_ns) && have_command_ && !command_.enable) {
    output_.watchdog_tripped = false;
  }

  const bool drive = have_command_ && command_.enable && !output_.watchdog_tripped &&
                     !output_.last_command_refused && !device_fault_;
  if (drive) {
    for (int axis = 0; axis < 3; ++axis) output_.force_n[axis] = command_.force_n[axis];
    for (int axis = 0; axis < 2; ++axis) output_.torque_nmm[axis] = command_.torque_nmm[axis];
    output_.force_applied = true;
  } else {
    zero_output();
  }

  ++sample_counter_;
  ++heartbeat_;
  const SimulatedPose pose = source_(sample_counter_, now_ns);
  hal::HapticSample sample{};
  for (int axis = 0; axis < 3; ++axis) sample.position_mm[axis] = pose.position_mm[axis];
  for (int angle = 0; angle < 2; ++angle) sample.angles_rad[angle] = pose.angles_rad[angle];
  sample.sample_counter = sample_counter_;
  sample.device_heartbeat = heartbeat_;
  sample.status_bits = (output_.force_applied ? hal::haptic_status::kForceApplied : 0U) |
                       (output_.watchdog_tripped ? hal::haptic_status::kHostWatchdogTripped : 0U) |
                       (output_.last_command_refused ? hal::haptic_status::kCommandRejected : 0U) |
                       (device_fault_ ? hal::haptic_status::kDeviceFault : 0U);
  link_.publish(sample);
  output_.samples_written = sample_counter_;
}

PoseSource scripted_trajectory(const SimulatedPose* waypoints, std::size_t count, hal::MonotonicNs start_ns,
                               hal::MonotonicNs segment_ns) {
  std::vector<SimulatedPose> points(waypoints, waypoints + count);
  return [points = std::move(points), start_ns, segment_ns](std::uint32_t, hal::MonotonicNs now_ns) {
    if (points.empty()) return SimulatedPose{};
    const double segments = static_cast<double>(now_ns - start_ns) / static_cast<double>(segment_ns);
    if (segments <= 0.0) return points.front();
    const auto index = static_cast<std::size_t>(segments);
    if (index + 1 >= points.size()) return points.back();
    const double fraction = segments - static_cast<double>(index);
    SimulatedPose pose{};
    const SimulatedPose& from = points[index];
    const SimulatedPose& to = points[index + 1];
    for (int axis = 0; axis < 3; ++axis) {
      pose.position_mm[axis] = from.position_mm[axis] + fraction * (to.position_mm[axis] - from.position_mm[axis]);
    }
    for (int angle = 0; angle < 2; ++angle) {
      pose.angles_rad[angle] = from.angles_rad[angle] + fraction * (to.angles_rad[angle] - from.angles_rad[angle]);
    }
    return pose;
  };
}

}  // namespace stencil::sim
