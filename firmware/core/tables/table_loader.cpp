// Validation of table bytes, in the order that lets each check trust the ones before it.
#include "firmware/core/tables/table_loader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <zlib.h>

#include "firmware/core/geometry/kdop14.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/tables/leaf_moments.hpp"
#include "firmware/core/tables/tool_section.hpp"

namespace stencil::tables {
namespace {

// Normals are stored as floats: a unit vector rounds to a length within a few 1e-7 of 1.
constexpr double kUnitLengthTolerance = 1e-5;

TableLoadResult ok() { return {true, nullptr, nullptr, 0, 0.0}; }

}  // namespace

const char* const kOlderVersion = "format version 5 (an older format: regenerate the table with stencil-tablegen)";  // names kTableFormatVersion: see check_header

namespace {

TableLoadResult refuse(const char* field, const char* expected, std::uint64_t index, double value) {
  return {false, field, expected, index, value};
}

struct ElementSize {
  TableSection section;
  const char* name;
  std::size_t element_bytes;
};

constexpr std::array<ElementSize, kSectionCount> kSectionElements = {{
    {TableSection::Tool, "sections.tool", sizeof(ToolSection)},
    {TableSection::Points, "sections.points", sizeof(PackedPoint)},
    {TableSection::Leaves, "sections.leaves", sizeof(LeafBlock)},
    {TableSection::TriangleIds, "sections.triangle_ids", sizeof(std::uint32_t)},
    {TableSection::PointFlags, "sections.point_flags", sizeof(std::uint8_t)},
    {TableSection::Triangles, "sections.triangles", sizeof(PackedTriangle)},
    {TableSection::TriangleFlags, "sections.triangle_flags", sizeof(std::uint8_t)},
    {TableSection::Nodes, "sections.nodes", sizeof(BvhNode)},
}};

std::uint64_t element_count(const TableHeader& header, TableSection section) {
  switch (section) {
    case TableSection::Tool:
      return 1;
    case TableSection::Points:
    case TableSection::TriangleIds:
    case TableSection::PointFlags:
      return header.point_count;
    case TableSection::Triangles:
    case TableSection::TriangleFlags:
      return header.triangle_count;
    case TableSection::Nodes:
      return header.node_count;
    case TableSection::Leaves:
      return header.leaf_count;
    case TableSection::Count:
      break;
  }
  return 0;
}

bool finite_point(const PackedPoint& point) {
  return std::isfinite(point.x_mm) && std::isfinite(point.y_mm) && std::isfinite(point.z_mm);
}

double first_non_finite(const PackedPoint& point) {
  return !std::isfinite(point.x_mm) ? double{point.x_mm} : !std::isfinite(point.y_mm) ? double{point.y_mm} : double{point.z_mm};
}

Eigen::Vector3d to_vector(const PackedPoint& point) { return {point.x_mm, point.y_mm, point.z_mm}; }

TableLoadResult check_header(std::span<const std::byte> bytes, const TableHeader& header) {
  if (std::memcmp(header.magic, kTableMagic, sizeof(kTableMagic)) != 0) {
    return refuse("header.magic", "the bytes \"STENCILT\" (not a stencil table file)", 0, 0.0);
  }
  if (header.format_version != kTableFormatVersion) {
    // Earlier versions are tables this build could read once: they are to be made again, not repaired.
    static_assert(kTableFormatVersion == 5, "the texts below name the version");
    return refuse("header.format_version",
                  header.format_version >= 1 && header.format_version < kTableFormatVersion
                      ? kOlderVersion
                      : "format version 5 (not a version this build knows: from a newer stencil-tablegen, or damaged)",
                  8, header.format_version);
  }
  if (header.header_bytes != sizeof(TableHeader)) {
    return refuse("header.header_bytes", "512", 12, header.header_bytes);
  }
  if (header.file_bytes != bytes.size()) {
    return refuse("header.file_bytes", "the size of the table (the file is truncated or has extra bytes)", 24,
                  static_cast<double>(header.file_bytes));
  }
  const std::uint32_t crc = table_crc32(bytes);
  if (crc != header.crc32) {
    return refuse("header.crc32", "the CRC-32 of the bytes after it (the table is corrupted)", 16, crc);
  }
  if (header.flags != 0) {
    return refuse("header.flags", "0", 20, header.flags);
  }
  if (header.point_count == 0 || header.point_count > kMaxTablePoints) {
    return refuse("header.point_count", "between 1 and 4194304", 36, header.point_count);
  }
  if (header.triangle_count == 0 || header.triangle_count > kMaxTableTriangles) {
    return refuse("header.triangle_count", "between 1 and 2097152", 32, header.triangle_count);
  }
  if (header.node_count == 0 || header.node_count > kMaxTableNodes) {
    return refuse("header.node_count", "between 1 and 1048576", 40, header.node_count);
  }
  if (header.leaf_count == 0 || header.leaf_count > header.node_count || header.leaf_count > header.point_count) {
    return refuse("header.leaf_count", "between 1 and node_count, at most point_count", 308, header.leaf_count);
  }
  if (header.vertex_point_count > header.point_count) {
    return refuse("header.vertex_point_count", "at most point_count", 44, header.vertex_point_count);
  }
  std::uint64_t previous_end = sizeof(TableHeader);
  for (const ElementSize& element : kSectionElements) {
    const SectionEntry& entry = header.sections[static_cast<std::size_t>(element.section)];
    if (entry.offset % kSectionAlignment != 0 || entry.offset < previous_end || entry.offset > bytes.size()) {
      return refuse(element.name, "an offset that is a multiple of 64, after the previous section, inside the file",
                    static_cast<std::uint64_t>(element.section), static_cast<double>(entry.offset));
    }
    if (entry.bytes != element_count(header, element.section) * element.element_bytes ||
        entry.bytes > bytes.size() - entry.offset) {
      return refuse(element.name, "count times element size, inside the file",
                    static_cast<std::uint64_t>(element.section), static_cast<double>(entry.bytes));
    }
    previous_end = entry.offset + entry.bytes;
  }
  struct NamedNumber {
    const char* name;
    double value;
    std::uint64_t offset;
  };
  const NamedNumber numbers[] = {
      {"header.covering_radius_mm", header.covering_radius_mm, offsetof(TableHeader, covering_radius_mm)},
      {"header.requested_spacing_mm", header.requested_spacing_mm, offsetof(TableHeader, requested_spacing_mm)},
      {"header.gouge_bound_mm", header.gouge_bound_mm, offsetof(TableHeader, gouge_bound_mm)},
      {"header.allowance_mm", header.allowance_mm, offsetof(TableHeader, allowance_mm)},
      {"header.stl_to_world_scale", header.stl_to_world_scale, offsetof(TableHeader, stl_to_world_scale)},
  };
  for (const NamedNumber& number : numbers) {
    if (!std::isfinite(number.value) || number.value < 0.0) {
      return refuse(number.name, "finite, not negative", number.offset, number.value);
    }
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(header.workspace_mm[axis]) || header.workspace_mm[axis] <= 0.0) {
      return refuse("header.workspace_mm", "finite and positive", 256 + 8 * axis, header.workspace_mm[axis]);
    }
  }
  return ok();
}

TableLoadResult check_tool(const TableHeader& header, const ToolSection& stored, geometry::ToolBsp& tool) {
  if (header.tool_kind > static_cast<std::uint32_t>(geometry::CutterKind::BullNose)) {
    return refuse("header.tool_kind", "0 (flat), 1 (ball) or 2 (bull-nose)", 304, header.tool_kind);
  }
  const geometry::ToolBuildResult built = geometry::build_tool_bsp(tool_spec_of(header), tool);
  if (!built.ok) {
    return refuse(built.field, built.expected, 312, built.value);
  }
  // The stored tree must be exactly the one the spec builds: a tree that only looks well-formed
  // could still classify wrongly.
  ToolSection rebuilt;
  encode_tool_section(tool, rebuilt);
  if (std::memcmp(&rebuilt, &stored, sizeof(ToolSection)) != 0) {
    return refuse("tool", "the BSP tree built from the header's tool spec", 0, 0.0);
  }
  return ok();
}

TableLoadResult check_points(const PartTables& tables) {
  const std::uint32_t count = tables.point_count();
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!finite_point(tables.points[i])) {
      return refuse("points", "finite coordinates", i, first_non_finite(tables.points[i]));
    }
    if (tables.triangle_ids[i] >= tables.triangle_count()) {
      return refuse("triangle_ids", "less than triangle_count", i, tables.triangle_ids[i]);
    }
    if ((tables.point_flags[i] & ~kPointReachable) != 0) {
      return refuse("point_flags", "only the reachable bit", i, tables.point_flags[i]);
    }
  }
  for (std::uint32_t i = 0; i < tables.triangle_count(); ++i) {
    for (const PackedPoint& vertex : tables.triangles[i].vertices) {
      if (!finite_point(vertex)) {
        return refuse("triangles", "finite coordinates", i, first_non_finite(vertex));
      }
    }
    if ((tables.triangle_flags[i] & ~kTriangleReachable) != 0) {
      return refuse("triangle_flags", "only the reachable bit", i, tables.triangle_flags[i]);
    }
  }
  return ok();
}

bool same_float(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// The leaf's block: its run of points, lane for lane the very floats of the Points section (lanes
// past the count repeating the last), unit normals likewise, a sphere bounding the points, zeros
// where reserved.
TableLoadResult check_leaf_block(const PartTables& tables, const BvhNode& node, std::uint32_t leaf) {
  const LeafBlock& block = tables.leaves[leaf];
  if (block.first_point != node.first_point || block.point_count != node.point_count) {
    return refuse("leaves", "the run of points of its leaf node", leaf, block.first_point);
  }
  const Eigen::Vector3d centre(block.centre_mm[0], block.centre_mm[1], block.centre_mm[2]);
  if (!centre.allFinite() || !std::isfinite(block.radius_mm) || block.radius_mm < 0.0F) {
    return refuse("leaves.sphere", "a finite centre and a finite radius, not negative", leaf, block.radius_mm);
  }
  for (std::uint32_t lane = 0; lane < kMaxLeafPoints; ++lane) {
    const PackedPoint& point = tables.points[node.first_point + std::min(lane, node.point_count - 1)];
    if (!same_float(block.x_mm[lane], point.x_mm) || !same_float(block.y_mm[lane], point.y_mm) ||
        !same_float(block.z_mm[lane], point.z_mm)) {
      return refuse("leaves.points", "the leaf's points as in the points section, the last repeated", leaf, lane);
    }
    const PackedPoint normal{block.nx[lane], block.ny[lane], block.nz[lane]};
    if (!finite_point(normal)) {
      return refuse("leaves.normals", "finite components", leaf, first_non_finite(normal));
    }
    const double length = to_vector(normal).norm();
    if (std::abs(length - 1.0) > kUnitLengthTolerance) {
      return refuse("leaves.normals", "unit length", leaf, length);
    }
    const std::uint32_t last = node.point_count - 1;
    if (lane > last && (!same_float(block.nx[lane], block.nx[last]) || !same_float(block.ny[lane], block.ny[last]) ||
                        !same_float(block.nz[lane], block.nz[last]))) {
      return refuse("leaves.normals", "past the leaf's points, its last point's normal", leaf, lane);
    }
    if ((to_vector(point) - centre).norm() > double{block.radius_mm}) {
      return refuse("leaves.sphere", "a sphere holding every point of the leaf", leaf, lane);
    }
  }
  const LeafMoments moments = leaf_moments(block);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (!same_float(block.centroid_mm[axis], moments.centroid_mm[axis])) {
      return refuse("leaves.centroid", "the mean of the leaf's points", leaf, block.centroid_mm[axis]);
    }
    if (!same_float(block.mean_normal[axis], moments.mean_normal[axis])) {
      return refuse("leaves.mean_normal", "the mean of the leaf's normals", leaf, block.mean_normal[axis]);
    }
  }
  for (std::uint32_t group = 0; group < kLeafGroups; ++group) {
    const LeafGroupMoments& expected = moments.groups[group];
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (!same_float(block.group_centroid_mm[axis][group], expected.centroid_mm[axis])) {
        return refuse("leaves.group_centroid", "the mean of each group's points (0 past the leaf's points)", leaf,
                      block.group_centroid_mm[axis][group]);
      }
      if (!same_float(block.group_mean_normal[axis][group], expected.mean_normal[axis])) {
        return refuse("leaves.group_mean_normal", "the mean of each group's normals (0 past the leaf's points)", leaf,
                      block.group_mean_normal[axis][group]);
      }
    }
    if (!same_float(block.group_radius_mm[group], expected.radius_mm)) {
      return refuse("leaves.group_radius", "each group's farthest point from its centroid, rounded up", leaf,
                    block.group_radius_mm[group]);
    }
  }
  for (const std::uint8_t byte : block.reserved) {
    if (byte != 0) {
      return refuse("leaves.reserved", "0", leaf, byte);
    }
  }
  return ok();
}

bool dop_is_sane(const BvhNode& node) {
  for (std::size_t slab = 0; slab < geometry::kKdopSlabCount; ++slab) {
    if (!std::isfinite(node.dop_min[slab]) || !std::isfinite(node.dop_max[slab]) ||
        node.dop_min[slab] > node.dop_max[slab]) {
      return false;
    }
  }
  return true;
}

bool dop_holds(const BvhNode& outer, const BvhNode& inner) {
  for (std::size_t slab = 0; slab < geometry::kKdopSlabCount; ++slab) {
    if (inner.dop_min[slab] < outer.dop_min[slab] || inner.dop_max[slab] > outer.dop_max[slab]) {
      return false;
    }
  }
  return true;
}

bool dop_holds_point(const BvhNode& node, const PackedPoint& point) {
  const auto projection = geometry::kdop_projections(to_vector(point));
  for (std::size_t slab = 0; slab < geometry::kKdopSlabCount; ++slab) {
    if (projection[slab] < node.dop_min[slab] || projection[slab] > node.dop_max[slab]) {
      return false;
    }
  }
  return true;
}

// Walks the tree depth-first with a fixed stack and checks that the walk meets the nodes in array
// order (so every node is reached exactly once) and the leaves in point order (so they tile the
// points exactly once).
TableLoadResult check_tree(const PartTables& tables) {
  struct Pending {
    std::uint32_t node;
    std::uint32_t parent;  // == node for the root
    std::uint32_t depth;
  };
  std::array<Pending, kMaxTreeDepth + 1> stack{};
  std::size_t stack_size = 0;
  stack[stack_size++] = {0, 0, 1};
  std::uint32_t next_node = 0;
  std::uint32_t next_point = 0;
  std::uint32_t next_leaf = 0;
  while (stack_size > 0) {
    const Pending pending = stack[--stack_size];
    if (pending.node != next_node) {
      return refuse("nodes", "depth-first order: each child where the walk reaches it", next_node, pending.node);
    }
    ++next_node;
    const BvhNode& node = tables.nodes[pending.node];
    if (!dop_is_sane(node)) {
      return refuse("nodes.dop", "finite bounds with min <= max", pending.node, 0.0);
    }
    if (pending.node != pending.parent && !dop_holds(tables.nodes[pending.parent], node)) {
      return refuse("nodes.dop", "inside its parent's DOP", pending.node, pending.parent);
    }
    if (node.point_count > 0) {
      if (node.point_count > kMaxLeafPoints || node.first_point != next_point ||
          node.point_count > tables.point_count() - next_point) {
        return refuse("nodes.leaf", "the next run of at most 64 points", pending.node, node.first_point);
      }
      for (std::uint32_t i = node.first_point; i < node.first_point + node.point_count; ++i) {
        if (!dop_holds_point(node, tables.points[i])) {
          return refuse("nodes.dop", "bounds every point of the leaf", pending.node, i);
        }
      }
      if (node.leaf != next_leaf || next_leaf >= tables.leaf_count()) {
        return refuse("nodes.leaf_block", "the leaves numbered in depth-first order, fewer than leaf_count",
                      pending.node, node.leaf);
      }
      const TableLoadResult block = check_leaf_block(tables, node, next_leaf);
      if (!block.ok) {
        return block;
      }
      ++next_leaf;
      next_point += node.point_count;
      continue;
    }
    if (node.leaf != 0) {
      return refuse("nodes.leaf_block", "0 for an internal node", pending.node, node.leaf);
    }
    const std::uint32_t left = pending.node + 1;
    if (node.right_child <= left || node.right_child >= tables.node_count() || left >= tables.node_count()) {
      return refuse("nodes.right_child", "a later node, after the left child, inside the tree", pending.node,
                    node.right_child);
    }
    if (pending.depth >= kMaxTreeDepth || stack_size + 2 > stack.size()) {
      return refuse("nodes", "a tree at most 64 levels deep", pending.node, pending.depth);
    }
    stack[stack_size++] = {node.right_child, pending.node, pending.depth + 1};
    stack[stack_size++] = {left, pending.node, pending.depth + 1};
  }
  if (next_node != tables.node_count()) {
    return refuse("nodes", "every node reached from the root", next_node, tables.node_count());
  }
  if (next_leaf != tables.leaf_count()) {
    return refuse("header.leaf_count", "the number of leaves in the tree", next_leaf, tables.leaf_count());
  }
  if (next_point != tables.point_count()) {
    return refuse("nodes.leaf", "leaves covering every point", next_point, tables.point_count());
  }
  return ok();
}

}  // namespace

std::uint32_t table_crc32(std::span<const std::byte> bytes) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  if (bytes.size() <= kCrcStartOffset) {
    return static_cast<std::uint32_t>(crc);
  }
  const auto* data = reinterpret_cast<const Bytef*>(bytes.data()) + kCrcStartOffset;
  std::size_t remaining = bytes.size() - kCrcStartOffset;
  constexpr std::size_t kChunk = 1u << 30;  // zlib takes 32-bit lengths
  while (remaining > 0) {
    const std::size_t chunk = remaining < kChunk ? remaining : kChunk;
    crc = ::crc32(crc, data, static_cast<uInt>(chunk));
    data += chunk;
    remaining -= chunk;
  }
  return static_cast<std::uint32_t>(crc);
}

TableLoadResult load_tables(std::span<const std::byte> bytes, PartTables& tables) {
  tables = PartTables{};
  if (bytes.size() < sizeof(TableHeader)) {
    return refuse("header", "at least 512 bytes (the file is truncated)", 0, static_cast<double>(bytes.size()));
  }
  if (reinterpret_cast<std::uintptr_t>(bytes.data()) % alignof(BvhNode) != 0) {
    return refuse("bytes", "a buffer aligned to 8 bytes (a caller error, not a file error)", 0, 0.0);
  }
  PartTables candidate{};
  std::memcpy(&candidate.header, bytes.data(), sizeof(TableHeader));
  const TableHeader& header = candidate.header;
  TableLoadResult result = check_header(bytes, header);
  if (!result.ok) {
    return result;
  }
  const auto at = [&](TableSection section) {
    return bytes.data() + header.sections[static_cast<std::size_t>(section)].offset;
  };
  // Sections are 64-byte aligned within an 8-byte aligned buffer, so these views are aligned.
  ToolSection stored_tool;
  std::memcpy(&stored_tool, at(TableSection::Tool), sizeof(ToolSection));
  result = check_tool(header, stored_tool, candidate.tool);
  if (!result.ok) {
    return result;
  }
  candidate.points = reinterpret_cast<const PackedPoint*>(at(TableSection::Points));
  candidate.triangle_ids = reinterpret_cast<const std::uint32_t*>(at(TableSection::TriangleIds));
  candidate.point_flags = reinterpret_cast<const std::uint8_t*>(at(TableSection::PointFlags));
  candidate.triangles = reinterpret_cast<const PackedTriangle*>(at(TableSection::Triangles));
  candidate.triangle_flags = reinterpret_cast<const std::uint8_t*>(at(TableSection::TriangleFlags));
  candidate.nodes = reinterpret_cast<const BvhNode*>(at(TableSection::Nodes));
  candidate.leaves = reinterpret_cast<const LeafBlock*>(at(TableSection::Leaves));
  result = check_points(candidate);
  if (!result.ok) {
    return result;
  }
  result = check_tree(candidate);
  if (!result.ok) {
    return result;
  }
  tables = candidate;
  return ok();
}

}  // namespace stencil::tables
