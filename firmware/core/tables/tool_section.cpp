// Encoding of the tool tree and spec into the table's fixed layout.
#include "firmware/core/tables/tool_section.hpp"

#include <cstring>

namespace stencil::tables {

void encode_tool_section(const geometry::ToolBsp& tool, ToolSection& section) {
  std::memset(&section, 0, sizeof(section));
  section.surface_count = tool.surface_count;
  section.node_count = tool.node_count;
  section.region_count = tool.region_count;
  for (std::size_t i = 0; i < tool.surface_count && i < geometry::kMaxToolSurfaces; ++i) {
    const geometry::ImplicitSurface& surface = tool.surfaces[i];
    section.surfaces[i].kind = static_cast<std::uint8_t>(surface.kind);
    section.surfaces[i].solid_side = static_cast<std::int8_t>(surface.solid_side);
    section.surfaces[i].center_r_mm = surface.center_r_mm;
    section.surfaces[i].center_z_mm = surface.center_z_mm;
    section.surfaces[i].radius_mm = surface.radius_mm;
  }
  for (std::size_t i = 0; i < tool.node_count && i < geometry::kMaxToolNodes; ++i) {
    const geometry::BspNode& node = tool.nodes[i];
    section.nodes[i] = {static_cast<std::uint8_t>(node.test),
                        node.surface_a,
                        node.surface_b,
                        static_cast<std::uint8_t>(node.when_true.kind),
                        node.when_true.index,
                        static_cast<std::uint8_t>(node.when_false.kind),
                        node.when_false.index,
                        0};
  }
  for (std::size_t i = 0; i < tool.region_count && i < geometry::kMaxToolRegions; ++i) {
    section.regions[i].surface = tool.regions[i].surface;
    section.regions[i].face = static_cast<std::uint8_t>(tool.regions[i].face);
  }
}

geometry::ToolSpec tool_spec_of(const TableHeader& header) {
  return {static_cast<geometry::CutterKind>(header.tool_kind),
          header.tool_diameter_mm,
          header.tool_flute_length_mm,
          header.tool_corner_radius_mm,
          header.tool_holder_diameter_mm,
          header.tool_holder_length_mm};
}

void store_tool_spec(const geometry::ToolSpec& spec, TableHeader& header) {
  header.tool_kind = static_cast<std::uint32_t>(spec.kind);
  header.tool_diameter_mm = spec.diameter_mm;
  header.tool_flute_length_mm = spec.flute_length_mm;
  header.tool_corner_radius_mm = spec.corner_radius_mm;
  header.tool_holder_diameter_mm = spec.holder_diameter_mm;
  header.tool_holder_length_mm = spec.holder_length_mm;
}

}  // namespace stencil::tables
