// The simulated device's end of the PIO window: physical units to words and back.
#include "sim/haptic_device/pio_device_link.hpp"

#include "sim/haptic_device/wire_units.hpp"

namespace stencil::sim {

namespace pio = hal::pio_shared_memory;

PioDeviceLink::PioDeviceLink(pio::SharedWindow& window) : side_(window) { side_.initialise_header(); }

void PioDeviceLink::publish(const hal::HapticSample& sample) {
  pio::PoseWords words{};
  words.sample_counter = sample.sample_counter;
  for (int axis = 0; axis < 3; ++axis) words.position_um[axis] = saturated_units(sample.position_mm[axis], 1e3);
  for (int angle = 0; angle < 2; ++angle) words.angles_urad[angle] = saturated_units(sample.angles_rad[angle], 1e6);
  words.status_bits = sample.status_bits;
  words.device_heartbeat = sample.device_heartbeat;
  side_.publish_pose(words);
}

CommandPoll PioDeviceLink::poll(DeviceCommand& out) {
  pio::CommandWords words{};
  switch (side_.read_command(words)) {
    case pio::CommandReadStatus::New: break;
    case pio::CommandReadStatus::OutOfRange: return CommandPoll::Refused;
    case pio::CommandReadStatus::Unchanged:
    case pio::CommandReadStatus::Busy: return CommandPoll::None;
  }
  for (int axis = 0; axis < 3; ++axis) out.force_n[axis] = words.force_mn[axis] * 1e-3;
  for (int axis = 0; axis < 2; ++axis) out.torque_nmm[axis] = words.torque_mnmm[axis] * 1e-3;
  out.cycle_counter = words.cycle_counter;
  out.host_heartbeat = words.host_heartbeat;
  out.enable = (words.flags & pio::kCommandEnableBit) != 0U;
  return CommandPoll::New;
}

}  // namespace stencil::sim
