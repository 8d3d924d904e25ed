// The cycle's configuration, the same way for every board.
#include "firmware/runtime/cycle_config.hpp"

namespace stencil::runtime {
control::ControllerConfig controller_config(const CycleFacts& facts) {
  control::ControllerConfig config;
  config.frames = facts.frames;
  config.contact.device_mm_per_world_mm = facts.frames.device_mm_per_world_mm;
  config.haptic.device_mm_per_world_mm = facts.frames.device_mm_per_world_mm;
  config.haptic.max_force_n = facts.force_limit_n;
  config.haptic.max_torque_nmm = facts.torque_limit_nmm;
  config.period_s = facts.period_s;
  config.device_low_mm = Eigen::Vector3d::Constant(-facts.device_reach_margin_mm);
  config.device_high_mm = facts.device_workspace_mm + Eigen::Vector3d::Constant(facts.device_reach_margin_mm);
  config.home_tip_mm = facts.frames.home_world_mm;
  config.count_overruns = facts.count_overruns;
  config.standoff_mm = facts.standoff_mm;
  // Per period: the virtual tool is held to what the mill follows.
  config.max_axis_move_mm = facts.virtual_tool_speed_mm_per_s * facts.period_s;
  config.max_total_move_mm = facts.virtual_tool_speed_mm_per_s * facts.period_s;
  return config;
}

}  // namespace stencil::runtime
