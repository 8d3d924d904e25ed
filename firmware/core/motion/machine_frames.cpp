// Device, world and machine coordinates.
#include "firmware/core/motion/machine_frames.hpp"

#include <cmath>

namespace stencil::motion {

Eigen::Vector3d device_to_world(const MachineFrames& frames, const Eigen::Vector3d& device_mm) {
  return (device_mm - frames.device_origin_mm) / frames.device_mm_per_world_mm;
}

Eigen::Vector3d world_to_device(const MachineFrames& frames, const Eigen::Vector3d& world_mm) {
  return world_mm * frames.device_mm_per_world_mm + frames.device_origin_mm;
}

bool world_to_steps(const MachineFrames& frames, const Eigen::Vector3d& world_mm, MachineSteps& steps) {
  for (int i = 0; i < 3; ++i) {
    const double exact = frames.machine_sign[static_cast<std::size_t>(i)] * (world_mm[i] - frames.home_world_mm[i]) *
                         frames.steps_per_mm;
    if (!std::isfinite(exact) || std::abs(exact) > kMaxMachineSteps) {
      return false;
    }
    steps.axis[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(std::lround(exact));
  }
  return true;
}

Eigen::Vector3d steps_to_world(const MachineFrames& frames, const MachineSteps& steps) {
  Eigen::Vector3d world;
  for (int i = 0; i < 3; ++i) {
    const auto axis = static_cast<std::size_t>(i);
    world[i] = frames.home_world_mm[i] +
               frames.machine_sign[axis] * static_cast<double>(steps.axis[axis]) / frames.steps_per_mm;
  }
  return world;
}

Eigen::Vector3d world_to_machine_mm(const MachineFrames& frames, const Eigen::Vector3d& world_mm) {
  Eigen::Vector3d machine;
  for (int i = 0; i < 3; ++i) {
    machine[i] = frames.machine_sign[static_cast<std::size_t>(i)] * (world_mm[i] - frames.home_world_mm[i]);
  }
  return machine;
}

}  // namespace stencil::motion
