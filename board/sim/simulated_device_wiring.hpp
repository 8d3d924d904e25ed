// The simulated haptic device as the cycle sees it, by the chosen transport: in process, or through
// the real backends' code over a memfd window (the PIO card's layout) or a socketpair carrying CAN
// frames; and the device's side of an injected fault.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "board/sim/fault_injection.hpp"
#include "board/sim/sim_job.hpp"
#include "hal/haptic_device.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/direct_haptic_device.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "sim/operator/operator_script.hpp"

namespace stencil::board::sim {

// The hand's handle is where the device's samples say; rendered_force() is what the device's motors
// drive now.
class SimulatedDeviceWiring {
 public:
  // `hand` must outlive the wiring: the device samples its handle. Not ready() when the transport
  // could not be set up (`error` says why).
  SimulatedDeviceWiring(HapticTransport transport, const hal::HapticRange& range, const stencil::sim::OperatorHand& hand,
                        std::string& error);
  SimulatedDeviceWiring(const SimulatedDeviceWiring&) = delete;
  SimulatedDeviceWiring& operator=(const SimulatedDeviceWiring&) = delete;
  ~SimulatedDeviceWiring();

  [[nodiscard]] bool ready() const { return transport_ == HapticTransport::Direct || simulated_ != nullptr; }
  [[nodiscard]] stencil::sim::SimulatedHapticDevice* simulated() { return simulated_.get(); }
  [[nodiscard]] hal::HapticDevice& host() { return transport_ == HapticTransport::Direct ? direct_ : *host_; }

  // The device's millisecond: a new sample of the handle, the host's newest command taken.
  void device_cycle(const stencil::sim::OperatorHand& hand, const Eigen::Vector2d& angles, hal::MonotonicNs now_ns);

  // The device's side of an injected fault.
  void inject(FaultKind kind);

  // Zero force at the device: the command it drives (direct) or its own output (over a wire).
  [[nodiscard]] bool force_off() const;
  [[nodiscard]] Eigen::Vector3d rendered_force() const;

 private:
  [[nodiscard]] Eigen::Vector3d disturbed(const Eigen::Vector3d& handle) const;

  HapticTransport transport_;
  stencil::sim::DirectHapticDevice direct_;
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> window_;
  std::unique_ptr<hal::socketcan::FdCanChannel> host_channel_, device_channel_;
  std::unique_ptr<stencil::sim::DeviceSideLink> device_link_;
  stencil::sim::CanDeviceLink* can_device_link_ = nullptr;  // device_link_, over CAN
  // The backends' destructors are theirs (HapticDevice's is protected): one owner each.
  std::unique_ptr<hal::pio_shared_memory::PioHapticDevice> pio_host_;
  std::unique_ptr<hal::socketcan::SocketCanHapticDevice> can_host_;
  hal::HapticDevice* host_ = nullptr;
  bool frozen_ = false, nan_ = false, jump_ = false, device_fault_ = false;
  std::unique_ptr<stencil::sim::SimulatedHapticDevice> simulated_;
  std::uint32_t counter_ = 0;
};

}  // namespace stencil::board::sim
