// What the mill can follow: the speed limits the virtual tool must keep so the machine never
// falls behind, and the per-update step budget the planner spends.
#pragma once

#include <Eigen/Core>

namespace stencil::motion {

struct MachineSpeed {
  double max_axis_speed_mm_per_s;  // each axis on its own (1.4 on the Sherline)
  double step_rate_steps_per_s;    // all axes together: the CY545 steps one axis at a time (~1000)
  double steps_per_mm;
};

// The move from `from_mm` towards `to_mm` shortened (same direction) so that in dt_s no axis moves
// faster than max_axis_speed and the axes' steps together stay within the step rate. The cycle
// applies it to the virtual tool: a faster hand is felt as the coupling pulling back, and the
// mill never lags by more than it can make up. Allocation-free.
[[nodiscard]] Eigen::Vector3d limit_tool_move(const MachineSpeed& speed, const Eigen::Vector3d& from_mm,
                                              const Eigen::Vector3d& to_mm, double dt_s);

}  // namespace stencil::motion
