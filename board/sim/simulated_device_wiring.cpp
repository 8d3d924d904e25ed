// The simulated device's transports, and what an injected fault does to it.
#include "board/sim/simulated_device_wiring.hpp"

#include "board/sim/sim_facts.hpp"

#include <limits>

#include <sys/socket.h>

#include "sim/haptic_device/pio_device_link.hpp"

namespace stencil::board::sim {

SimulatedDeviceWiring::SimulatedDeviceWiring(HapticTransport transport, const hal::HapticRange& range,
                                             const stencil::sim::OperatorHand& hand, std::string& error)
    : transport_(transport), direct_(range) {
  const auto pose = [&hand, this](std::uint32_t, hal::MonotonicNs) {
    const Eigen::Vector3d at = disturbed(hand.handle_mm);
    return stencil::sim::SimulatedPose{{at.x(), at.y(), at.z()}, {0.0, 0.0}};
  };
  if (transport == HapticTransport::Pio) {
    window_ = hal::pio_shared_memory::SharedWindowMapping::create_memfd("stencil-sim-pio", error);
    if (window_ == nullptr) {
      return;
    }
    device_link_ = std::make_unique<stencil::sim::PioDeviceLink>(window_->window());
    pio_host_ = std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&window_->window(), range);
    host_ = pio_host_.get();
  } else if (transport == HapticTransport::Can) {
    int fds[2] = {-1, -1};
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0, fds) != 0) {
      error = "socketpair for the simulated CAN bus failed";
      return;
    }
    host_channel_ = std::make_unique<hal::socketcan::FdCanChannel>(fds[0]);
    device_channel_ = std::make_unique<hal::socketcan::FdCanChannel>(fds[1]);
    auto can_link = std::make_unique<stencil::sim::CanDeviceLink>(*device_channel_);
    can_device_link_ = can_link.get();
    device_link_ = std::move(can_link);
    can_host_ = std::make_unique<hal::socketcan::SocketCanHapticDevice>(host_channel_.get(), range);
    host_ = can_host_.get();
  }
  if (device_link_ != nullptr) {
    simulated_ = std::make_unique<stencil::sim::SimulatedHapticDevice>(*device_link_, pose);
  }
}

SimulatedDeviceWiring::~SimulatedDeviceWiring() = default;

void SimulatedDeviceWiring::device_cycle(const stencil::sim::OperatorHand& hand, const Eigen::Vector2d& angles,
                                         hal::MonotonicNs now_ns) {
  if (transport_ == HapticTransport::Direct) {
    if (frozen_) {
      return;
    }
    ++counter_;
    const Eigen::Vector3d at = disturbed(hand.handle_mm);
    direct_.publish({{at.x(), at.y(), at.z()}, {angles.x(), angles.y()}, counter_,
                     hal::haptic_status::kForceApplied | (device_fault_ ? hal::haptic_status::kDeviceFault : 0U), counter_});
  } else {
    simulated_->step(now_ns);
  }
  jump_ = false;  // a jump is one sample
}

void SimulatedDeviceWiring::inject(FaultKind kind) {
  switch (kind) {
    case FaultKind::DeviceFrozen:
      frozen_ = true;
      if (simulated_ != nullptr) {
        simulated_->set_frozen(true);
      }
      break;
    case FaultKind::PoseNan:
      nan_ = true;
      break;
    case FaultKind::PoseJump:
      jump_ = true;
      break;
    case FaultKind::CanBadFrames:
      if (can_device_link_ != nullptr) {
        can_device_link_->babble(20);
      }
      break;
    case FaultKind::DeviceFault:
      device_fault_ = true;
      if (simulated_ != nullptr) {
        simulated_->set_device_fault(true);
      }
      break;
    default:
      break;
  }
}

bool SimulatedDeviceWiring::force_off() const {
  if (transport_ == HapticTransport::Direct) {
    return !direct_.rendered().enable || rendered_force().norm() == 0.0;
  }
  return !simulated_->output().force_applied || rendered_force().norm() == 0.0;
}

Eigen::Vector3d SimulatedDeviceWiring::rendered_force() const {
  if (transport_ == HapticTransport::Direct) {
    const hal::HapticCommand& c = direct_.rendered();
    return {c.force_n[0], c.force_n[1], c.force_n[2]};
  }
  const stencil::sim::DeviceOutput output = simulated_->output();
  return {output.force_n[0], output.force_n[1], output.force_n[2]};
}

Eigen::Vector3d SimulatedDeviceWiring::disturbed(const Eigen::Vector3d& handle) const {
  if (nan_) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return jump_ ? Eigen::Vector3d(handle + Eigen::Vector3d(100.0, 0.0, 0.0)) : handle;
}

}  // namespace stencil::board::sim
