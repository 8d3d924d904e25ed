// A validated part: read-only views into the table bytes, plus the tool it was generated for.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::tables {

// Views into bytes that the caller owns and keeps alive (static storage on the rig, the baked-in
// section, or a test's buffer). Only load_tables() fills one, after every check has passed.
struct PartTables {
  TableHeader header;                 // a copy
  geometry::ToolBsp tool;             // rebuilt from the header's tool spec and equal to the file's tree
  const PackedPoint* points;          // [header.point_count]
  const PackedPoint* normals;         // [header.point_count]
  const std::uint32_t* triangle_ids;  // [header.point_count]
  const std::uint8_t* point_flags;    // [header.point_count]
  const PackedTriangle* triangles;    // [header.triangle_count]
  const std::uint8_t* triangle_flags; // [header.triangle_count]
  const BvhNode* nodes;               // [header.node_count], root first

  [[nodiscard]] std::uint32_t point_count() const { return header.point_count; }
  [[nodiscard]] std::uint32_t triangle_count() const { return header.triangle_count; }
  [[nodiscard]] std::uint32_t node_count() const { return header.node_count; }
};

}  // namespace stencil::tables
