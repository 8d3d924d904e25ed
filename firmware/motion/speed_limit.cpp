// The virtual tool's speed limit.
#include "firmware/motion/speed_limit.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::motion {

Eigen::Vector3d limit_tool_move(const MachineSpeed& speed, const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm,
                                double dt_s) {
  const Eigen::Vector3d move = to_mm - from_mm;
  if (!move.allFinite() || !(dt_s > 0.0)) {
    return from_mm;
  }
  const double axis_reach = speed.max_axis_speed_mm_per_s * dt_s;
  const double total_reach = speed.step_rate_steps_per_s / speed.steps_per_mm * dt_s;  // along x, y, z together
  const double largest = move.cwiseAbs().maxCoeff();
  const double total = move.cwiseAbs().sum();
  double scale = 1.0;
  if (largest > axis_reach) {
    scale = axis_reach / largest;
  }
  if (total * scale > total_reach) {
    scale = total_reach / total;
  }
  return scale == 1.0 ? to_mm : Eigen::Vector3d(from_mm + scale * move);
}

}  // namespace stencil::motion
