// The three spaces the controller works in and the maps between them: the device (haptic handle,
// mm), the world (the part's own coordinates, mm, = the machine workspace) and the machine (motor
// steps per axis, counted from home).
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace stencil::motion {

// A position of the mill in motor steps per axis (x, y, z), counted from home.
struct MachineSteps {
  std::array<std::int32_t, 3> axis;

  friend bool operator==(const MachineSteps&, const MachineSteps&) = default;
};

struct MachineFrames {
  double device_mm_per_world_mm;      // the haptic-to-machine scale (10 on the rig)
  Eigen::Vector3d device_origin_mm;   // the device point that maps to the world origin
  Eigen::Vector3d home_world_mm;      // where the tool tip is in the world when the machine is at home
  std::array<int, 3> machine_sign;    // +1 or -1: a machine axis counts along (+1) or against (-1) the
                                      // world axis; the Sherline's X and Y move the table, so the work
                                      // moves under the tool: those are -1
  double steps_per_mm;                // every axis
};

[[nodiscard]] Eigen::Vector3d device_to_world(const MachineFrames& frames, const Eigen::Vector3d& device_mm);
[[nodiscard]] Eigen::Vector3d world_to_device(const MachineFrames& frames, const Eigen::Vector3d& world_mm);

// The machine position that puts the tool tip at world_mm, rounded to the nearest step. False when
// a coordinate is not finite or beyond what 24 bits of steps can hold (the CY545's range).
[[nodiscard]] bool world_to_steps(const MachineFrames& frames, const Eigen::Vector3d& world_mm, MachineSteps& steps);
[[nodiscard]] Eigen::Vector3d steps_to_world(const MachineFrames& frames, const MachineSteps& steps);
// A world point in machine coordinates (mm from home along each machine axis, its sign), as a
// machine's position readout shows it: the motor steps it takes, over the steps per mm, unrounded.
[[nodiscard]] Eigen::Vector3d world_to_machine_mm(const MachineFrames& frames, const Eigen::Vector3d& world_mm);

// The CY545 holds positions and step counts in 24 bits (signed here).
inline constexpr std::int32_t kMaxMachineSteps = (1 << 23) - 1;

}  // namespace stencil::motion
