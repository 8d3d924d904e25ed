// The tool tree's file form: every byte defined, so equal trees give equal bytes.
#pragma once

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_spec.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::tables {

static_assert(sizeof(ToolSection::surfaces) / sizeof(ToolSectionSurface) == geometry::kMaxToolSurfaces);
static_assert(sizeof(ToolSection::nodes) / sizeof(ToolSectionNode) == geometry::kMaxToolNodes);
static_assert(sizeof(ToolSection::regions) / sizeof(ToolSectionRegion) == geometry::kMaxToolRegions);

// Writes the tree into `section`, zeroing every unused and reserved byte first.
void encode_tool_section(const geometry::ToolBsp& tool, ToolSection& section);

// The tool spec as the header stores it.
[[nodiscard]] geometry::ToolSpec tool_spec_of(const TableHeader& header);
void store_tool_spec(const geometry::ToolSpec& spec, TableHeader& header);

}  // namespace stencil::tables
