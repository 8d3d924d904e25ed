// The standoff: the part as the cycle's engine sees it, with the tool grown by a small distance all
// round, so that the virtual tool keeps that far clear of the part while the real tool's tip is
// where the mill goes. The mill steps one axis at a time on a grid of 1/640 mm; a virtual tool that
// ran a micrometre off the part (closer than one step) left it no legal staircase along a curved
// or cornered path however finely it was cut. With the standoff, every staircase the planner needs
// stays within the standoff of a pose the virtual tool held, so it is legal (the argument is
// motion::kFollowStandoffArgument's, in machine_planner.hpp). The cost: the operator feels the wall
// the standoff out, and that much stock is left on the part.
#pragma once

#include <Eigen/Core>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_spec.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::engine {

// The largest standoff the engine takes: anything near a millimetre is a typing error, not a stock
// allowance (the operator would feel the wall a visible distance off the part).
inline constexpr double kMaxStandoff_mm = 0.5;

struct StandoffPart {
  // The tables' views with `tool` grown by standoff_mm (tools contain the real tool moved anywhere
  // within standoff_mm: see grow_tool_for_standoff) and the workspace's top lowered by as much, in
  // the engine's frame: the grown tool's tip, standoff_mm below the real tool's.
  tables::PartTables part;
  double standoff_mm = 0.0;

  // The real tool's tip to the engine's (the grown tool's tip) and back.
  [[nodiscard]] Eigen::Vector3d to_engine(const Eigen::Vector3d& tip_mm) const {
    return {tip_mm.x(), tip_mm.y(), tip_mm.z() - standoff_mm};
  }
  [[nodiscard]] Eigen::Vector3d to_tip(const Eigen::Vector3d& engine_mm) const {
    return {engine_mm.x(), engine_mm.y(), engine_mm.z() + standoff_mm};
  }
};

// The tool that, with its tip standoff_mm below the real tool's, contains the real tool moved by
// any vector no longer than standoff_mm (the Minkowski sum with a ball): the cutter's radius and
// the holder's grow by it, the cutter's flutes keep their length (the holder's underside must come
// standoff_mm lower, as the real holder moved down would), the holder grows by twice it upwards, a
// bull-nose corner's radius by it. False when the grown spec is not a valid tool.
[[nodiscard]] bool grow_tool_for_standoff(const geometry::ToolSpec& spec, double standoff_mm, geometry::ToolBsp& grown);

// `view` for `part` and standoff_mm (0: the part as it is). Init time. False, with `view` untouched,
// when standoff_mm is not finite, negative, over kMaxStandoff_mm or over the workspace's height, or
// the grown tool is not valid.
[[nodiscard]] bool build_standoff_part(const tables::PartTables& part, double standoff_mm, StandoffPart& view);

}  // namespace stencil::engine
