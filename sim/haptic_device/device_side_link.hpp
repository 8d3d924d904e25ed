// DeviceSideLink: the device's end of an exchange with the host (the PIO window or the CAN bus), in
// physical units, as the simulated device uses it. Not real-time code.
#pragma once

#include <cstdint>

#include "hal/haptic_device.hpp"

namespace stencil::sim {

// A command as the device decoded it.
struct DeviceCommand {
  double force_n[3];
  double torque_nmm[2];
  std::uint32_t cycle_counter;   // as the wire carries it (8 bits on CAN)
  std::uint32_t host_heartbeat;  // as the wire carries it (16 bits on CAN)
  bool enable;
};

enum class CommandPoll : std::uint8_t {
  New,      // a command arrived and passed the device's checks: `out` holds the newest
  None,     // nothing new
  Refused,  // something arrived but the device refused it (beyond its limits, bad frames)
};

class DeviceSideLink {
 public:
  DeviceSideLink() = default;
  DeviceSideLink(const DeviceSideLink&) = delete;
  DeviceSideLink& operator=(const DeviceSideLink&) = delete;
  virtual ~DeviceSideLink() = default;

  // Writes one pose sample (all fields, as given: the link saturates what its wire cannot carry).
  virtual void publish(const hal::HapticSample& sample) = 0;

  // Takes what the host sent since the last poll; `out` is written only when New.
  [[nodiscard]] virtual CommandPoll poll(DeviceCommand& out) = 0;
};

}  // namespace stencil::sim
