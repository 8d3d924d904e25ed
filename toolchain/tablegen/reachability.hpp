// Which points a 3-axis mill can reach: a vertical tool touching the point along its normal,
// legal (no other point inside the tool) and with its tip inside the workspace.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::tablegen {

// Points deeper than this inside the tool make a pose illegal. Above the float rounding of the
// stored points (about 4e-6 mm at 50 mm), far below any gouge bound worth asking for.
inline constexpr double kReachTolerance_mm = 1e-3;

struct ReachInput {
  const std::vector<tables::PackedPoint>& points;   // in table order
  const std::vector<tables::PackedPoint>& normals;  // in table order
  const std::vector<tables::BvhNode>& nodes;
  const geometry::ToolBsp& tool;
  Eigen::Vector3d workspace_mm;
};

// Where the tool's tip goes so that its surface touches `point` with the tool's outward normal
// equal to minus `normal` (axis vertical). False when the normal faces down (no vertical tool can touch it).
[[nodiscard]] bool touching_tip(const geometry::ToolSpec& tool, const Eigen::Vector3d& point,
                                const Eigen::Vector3d& normal, Eigen::Vector3d& tip);

// Whether any point lies deeper than kReachTolerance_mm inside the vertical tool with its tip at `tip`.
[[nodiscard]] bool upright_tool_collides(const ReachInput& input, const Eigen::Vector3d& tip);

// kPointReachable for each point. The result does not depend on `threads`.
[[nodiscard]] std::vector<std::uint8_t> mark_reachable(const ReachInput& input, unsigned threads,
                                                       const std::function<void(double)>& progress);

}  // namespace stencil::tablegen
