// The 14-DOP that bounds a tool at a pose in the world (for the query against the part's tree).
#pragma once

#include <Eigen/Core>

#include "firmware/core/geometry/kdop14.hpp"
#include "firmware/core/geometry/tool_bsp.hpp"

namespace stencil::geometry {

// How far the bound reaches beyond the envelope's exact extent (mm).
inline constexpr double kToolBoundMargin_mm = 2.0 * kSurfaceTolerance_mm;

// The 14-DOP of the tool's envelope (cutter cylinder under holder cylinder) with its tip at tip_mm
// and its axis along unit_axis (unit length, from the tip up into the spindle), grown by
// kToolBoundMargin_mm. It holds every point of the tool and every point the BSP calls touching,
// whatever the cutter kind. Allocation-free.
[[nodiscard]] Kdop14 tool_kdop(const ToolEnvelope& envelope, const Eigen::Vector3d& tip_mm,
                               const Eigen::Vector3d& unit_axis);

}  // namespace stencil::geometry
