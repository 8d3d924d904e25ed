// The cycle's configuration, the same way for every board.
#include "firmware/runtime/cycle_config.hpp"

namespace stencil::runtime {
namespace {

// A sample this far outside the device's workspace (device mm) is still within its reach: the
// handle at the workspace's edge is not a fault.
constexpr double kReachMarginMm = 25.0;

}  // namespace

control::ControllerConfig controller_config(const CycleFacts& facts) {
  control::ControllerConfig config;
  config.frames = facts.frames;
  config.device_low_mm = Eigen::Vector3d::Constant(-kReachMarginMm);
  config.device_high_mm = facts.device_workspace_mm + Eigen::Vector3d::Constant(kReachMarginMm);
  config.home_tip_mm = facts.frames.home_world_mm;
  config.count_overruns = facts.count_overruns;
  // Per period (1 ms): the virtual tool is held to what the mill follows.
  config.max_axis_move_mm = facts.virtual_tool_speed_mm_per_s * 1e-3;
  config.max_total_move_mm = facts.virtual_tool_speed_mm_per_s * 1e-3;
  return config;
}

}  // namespace stencil::runtime
