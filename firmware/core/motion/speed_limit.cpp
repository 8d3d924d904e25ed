// The virtual tool's speed limit.
#include "firmware/core/motion/speed_limit.hpp"

#include "firmware/core/stencil/move_limit.hpp"

namespace stencil::motion {

Eigen::Vector3d limit_tool_move(const MachineSpeed& speed, const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm,
                                double dt_s) {
  if (!(to_mm - from_mm).allFinite() || !(dt_s > 0.0)) {
    return from_mm;
  }
  bool shortened = false;
  return engine::shorten_move(from_mm, to_mm, speed.max_axis_speed_mm_per_s * dt_s,
                              speed.step_rate_steps_per_s / speed.steps_per_mm * dt_s, shortened);
}

}  // namespace stencil::motion
