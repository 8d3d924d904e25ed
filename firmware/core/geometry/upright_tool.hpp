// Cheap, exact-enough tests for a tool standing upright (axis +z, as on the 3-axis mill): whether a
// box or a point can be inside it, without walking the BSP. Used to cull before the BSP decides.
#pragma once

#include <Eigen/Core>

#include "firmware/core/geometry/tool_bsp.hpp"

namespace stencil::geometry {

// Radius of the tool's widest cross-section at or below height z above the tip (mm): the tool
// widens upwards, since the holder is at least as wide as the cutter.
[[nodiscard]] double upright_radius_up_to(const ToolSpec& tool, double height_mm);

// False only when no point of the axis-aligned box [low, high] (world mm) can be deeper than
// margin_mm inside the upright tool with its tip at tip_mm. Allocation-free.
[[nodiscard]] bool upright_box_may_touch(const ToolBsp& tool, const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& low,
                                         const Eigen::Vector3d& high, double margin_mm);

// False only when the point (relative to the tip) cannot be deeper than margin_mm inside the
// upright tool: the outline tested with squares, so the BSP sees only the points that matter.
[[nodiscard]] bool upright_point_may_be_inside(const ToolBsp& tool, const Eigen::Vector3d& local_mm, double margin_mm);

}  // namespace stencil::geometry
