// Where the tool is: its tip in world millimetres and the unit direction of its axis (tip to spindle).
#pragma once

#include <Eigen/Core>

namespace stencil::engine {

struct ToolPose {
  Eigen::Vector3d tip_mm;
  Eigen::Vector3d axis;  // unit length; +z for the 3-axis mill
};

}  // namespace stencil::engine
