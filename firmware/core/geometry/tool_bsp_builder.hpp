// Builds a tool's BSP tree from its description (used by the table generator and at start-up).
#pragma once

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::geometry {

// No tool dimension may exceed this (mm): far beyond any desktop mill, it keeps nonsense out.
inline constexpr double kMaxToolDimension_mm = 1000.0;

// The builder's verdict. When ok is false, field names the ToolSpec member that is wrong,
// expected says what it must be, and value is what it was; the tree is left with no nodes.
struct ToolBuildResult {
  bool ok;
  const char* field;     // e.g. "diameter_mm"; nullptr when ok
  const char* expected;  // e.g. "a finite number greater than 0 and at most 1000"; nullptr when ok
  double value;
};

// Builds the tree of the described tool into `tool` (overwriting all of it). Allocation-free.
// Limits, each with its own error: every dimension finite and at most kMaxToolDimension_mm;
// diameter > 0; flute length at least the cutter radius; corner radius (bull-nose) > 0 and at most
// the cutter radius; holder diameter at least the cutter diameter; holder length at least the
// cutter radius. Within these limits every region's depth is the exact distance to the tool's surface.
[[nodiscard]] ToolBuildResult build_tool_bsp(const ToolSpec& spec, ToolBsp& tool);

}  // namespace stencil::geometry
