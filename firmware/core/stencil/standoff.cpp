// The standoff's view of the part.
#include "firmware/core/stencil/standoff.hpp"

#include <cmath>

#include "firmware/core/geometry/tool_bsp_builder.hpp"

namespace stencil::engine {

bool grow_tool_for_standoff(const geometry::ToolSpec& spec, double standoff_mm, geometry::ToolBsp& grown) {
  geometry::ToolSpec inflated = spec;
  inflated.diameter_mm += 2.0 * standoff_mm;
  inflated.corner_radius_mm += spec.kind == geometry::CutterKind::BullNose ? standoff_mm : 0.0;
  inflated.holder_diameter_mm += 2.0 * standoff_mm;
  inflated.holder_length_mm += 2.0 * standoff_mm;
  return geometry::build_tool_bsp(inflated, grown).ok;
}

bool build_standoff_part(const tables::PartTables& part, double standoff_mm, StandoffPart& view) {
  if (!std::isfinite(standoff_mm) || standoff_mm < 0.0 || standoff_mm > kMaxStandoff_mm ||
      !(standoff_mm < part.header.workspace_mm[2])) {
    return false;
  }
  StandoffPart built{part, standoff_mm};
  if (standoff_mm > 0.0) {
    if (!grow_tool_for_standoff(part.tool.spec, standoff_mm, built.part.tool)) {
      return false;
    }
    // The real tip's box is the workspace; the engine's tip is standoff_mm lower, so its box's top
    // is too, and its floor z = 0 keeps the real tip standoff_mm above the stock's floor.
    built.part.header.workspace_mm[2] -= standoff_mm;
  }
  view = built;
  return true;
}

}  // namespace stencil::engine
