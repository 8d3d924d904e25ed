// PioDeviceLink: the simulated device's end of the PIO shared memory window.
#pragma once

#include "hal/pio_shared_memory/pio_device_side.hpp"
#include "sim/haptic_device/device_side_link.hpp"

namespace stencil::sim {

class PioDeviceLink final : public DeviceSideLink {
 public:
  // Initialises the window's header (what the controller does at power-up). The window must outlive
  // this object.
  explicit PioDeviceLink(hal::pio_shared_memory::SharedWindow& window);

  void publish(const hal::HapticSample& sample) override;
  [[nodiscard]] CommandPoll poll(DeviceCommand& out) override;

  [[nodiscard]] const hal::pio_shared_memory::DeviceSideCounters& counters() const { return side_.counters(); }

 private:
  hal::pio_shared_memory::PioDeviceSide side_;
};

}  // namespace stencil::sim
