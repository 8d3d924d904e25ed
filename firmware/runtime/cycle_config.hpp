// The cycle's configuration from a board's facts: its frames, its device's reach and the speed its
// mill follows. A board sets what is its own on top (a held start, its watchdogs' limits).
#pragma once

#include <Eigen/Core>

#include "firmware/core/control/controller.hpp"
#include "firmware/core/motion/machine_frames.hpp"

namespace stencil::runtime {

struct CycleFacts {
  motion::MachineFrames frames;           // device -> world -> machine
  Eigen::Vector3d device_workspace_mm;    // the device's workspace, from its corner origin
  double device_reach_margin_mm;          // a sample this far outside the workspace is still a sample
  double force_limit_n;                   // what the device may push with
  double torque_limit_nmm;
  double period_s;                        // the cycle's
  double virtual_tool_speed_mm_per_s;     // what the mill follows, per axis and |dx| + |dy| + |dz|
  double standoff_mm;                     // the virtual tool keeps this clear of the part (ControllerConfig)
  bool count_overruns;                    // in real time; in virtual time lateness means nothing
};

[[nodiscard]] control::ControllerConfig controller_config(const CycleFacts& facts);

}  // namespace stencil::runtime
