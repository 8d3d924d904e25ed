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
  const std::uint32_t* triangle_ids;  // [header.point_count]
  const std::uint8_t* point_flags;    // [header.point_count]
  const PackedTriangle* triangles;    // [header.triangle_count]
  const std::uint8_t* triangle_flags; // [header.triangle_count]
  const BvhNode* nodes;               // [header.node_count], root first
  const LeafBlock* leaves;            // [header.leaf_count], in depth-first order of the leaves

  [[nodiscard]] std::uint32_t point_count() const { return header.point_count; }
  [[nodiscard]] std::uint32_t triangle_count() const { return header.triangle_count; }
  [[nodiscard]] std::uint32_t node_count() const { return header.node_count; }
  [[nodiscard]] std::uint32_t leaf_count() const { return header.leaf_count; }
};

// The unit normal of point `point` (< point_count), from its leaf's block: a binary search over the
// blocks, for tools and checks. The query reads a leaf's normals from its block directly.
[[nodiscard]] inline PackedPoint point_normal(const PartTables& tables, std::uint32_t point) {
  std::uint32_t low = 0;
  std::uint32_t high = tables.leaf_count();  // the block is the last one starting at or before `point`
  while (high - low > 1) {
    const std::uint32_t middle = low + (high - low) / 2;
    (tables.leaves[middle].first_point <= point ? low : high) = middle;
  }
  const LeafBlock& block = tables.leaves[low];
  const std::uint32_t lane = point - block.first_point;
  return {block.nx[lane], block.ny[lane], block.nz[lane]};
}

}  // namespace stencil::tables
