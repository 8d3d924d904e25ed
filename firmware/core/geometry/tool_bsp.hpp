// The tool as a BSP tree of implicit surfaces of (r, z), and point classification against it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include <Eigen/Core>

#include "firmware/core/geometry/implicit_surface.hpp"
#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::geometry {

// Capacities of a tool tree. The largest tool built today (bull-nose under a wider holder) uses
// 10 surfaces, 16 nodes and 7 regions; the rest is room for a further face or two.
inline constexpr std::size_t kMaxToolSurfaces = 16;
inline constexpr std::size_t kMaxToolNodes = 32;
inline constexpr std::size_t kMaxToolRegions = 8;

// A point inside the tool by no more than this is touching with depth 0: only depth beyond it is
// penetration. Points outside by about this much (up to sqrt(2) times it at a rim, where two
// boundary tests each allow it) may also be reported as touching; points farther out never are.
inline constexpr double kSurfaceTolerance_mm = 1e-9;

// Which face of the tool a region's points are nearest to (for display and diagnostics).
enum class ToolFace : std::uint8_t {
  Bottom,        // flat end face at the tip
  BallEnd,       // hemisphere of a ball end mill
  Corner,        // corner torus of a bull-nose end mill
  FluteSide,     // cylinder of the cutting part
  HolderStep,    // downward annulus where a wider holder starts
  HolderEdge,    // concave circular edge where the flutes meet a wider holder
  HolderSide,    // cylinder of the holder
  HolderTop,     // top of the holder
};

// An interior region: every point in it has `surface` as its nearest part of the tool's boundary,
// so the surface's interior distance is the penetration depth there.
struct ToolRegion {
  std::uint8_t surface;
  ToolFace face;
};

enum class NodeTest : std::uint8_t {
  // Is the point on the solid side of boundary surface `surface_a`, within kSurfaceTolerance_mm?
  InsideBoundary,
  // Is the point strictly below/inside partition surface `surface_a` (f < 0)? Exact.
  BelowPartition,
  // Is boundary surface `surface_a` at least as near as `surface_b`? The bisector of the two. Exact.
  NearerThan,
};

// Where a branch leads.
struct BspLink {
  enum class Kind : std::uint8_t { Node, Region, Outside };
  Kind kind;
  std::uint8_t index;  // node or region index; unused for Outside
};

struct BspNode {
  NodeTest test;
  std::uint8_t surface_a;
  std::uint8_t surface_b;  // NearerThan only
  BspLink when_true;
  BspLink when_false;
};

// The tool's dimensions that bound it: a cutter cylinder under a holder cylinder (mm).
struct ToolEnvelope {
  double cutter_radius_mm;
  double flute_length_mm;
  double holder_radius_mm;
  double total_length_mm;  // flutes plus holder
};

// A built tool: flat arrays of plain structs with indices instead of pointers, so the table
// generator can write it and the controller can load it byte for byte. Node 0 is the root and
// every link points to a later node, so a walk ends within node_count steps.
struct ToolBsp {
  ToolSpec spec;
  ToolEnvelope envelope;
  std::uint8_t surface_count;
  std::uint8_t node_count;
  std::uint8_t region_count;
  std::array<ImplicitSurface, kMaxToolSurfaces> surfaces;
  std::array<BspNode, kMaxToolNodes> nodes;
  std::array<ToolRegion, kMaxToolRegions> regions;
};

static_assert(std::is_trivially_copyable_v<ToolBsp>, "ToolBsp is serialised as-is");
static_assert(std::is_standard_layout_v<ToolBsp>, "ToolBsp is serialised as-is");

enum class PointContact : std::uint8_t {
  Outside,      // not in the tool
  Touching,     // on the tool's surface (within kSurfaceTolerance_mm): depth 0, no force
  Penetrating,  // inside the tool by depth_mm > 0
  BadTree,      // the tree is damaged (broken links, counts beyond capacity, NaN numbers) or the
                // point is not finite: treat as a fault, never as "no contact"
};

struct PointClassification {
  PointContact contact;
  std::uint8_t region;                 // valid for Touching and Penetrating
  double depth_mm;                     // distance to the tool's surface; 0 unless Penetrating
  Eigen::Vector3d escape_direction;    // unit: the way the point leaves the tool fastest (the
                                       // tool's outward normal at the nearest surface point);
                                       // zero when Outside or BadTree
};

// Classifies a point given in the tool frame (tip at origin, axis +z), mm. Allocation-free,
// bounded (at most node_count steps), no recursion, no virtual calls.
[[nodiscard]] PointClassification classify_in_tool_frame(const ToolBsp& tool, const Eigen::Vector3d& point_mm);

// Classifies a world point against the tool with its tip at tip_mm and its axis along unit_axis
// (unit length, pointing from the tip up into the spindle). Escape direction in world frame.
// Roll about the axis does not matter: the tool is a solid of revolution.
[[nodiscard]] PointClassification classify_at_pose(const ToolBsp& tool, const Eigen::Vector3d& tip_mm,
                                                   const Eigen::Vector3d& unit_axis,
                                                   const Eigen::Vector3d& point_mm);

// The region's classification in the meridian plane (used by both of the above and by tests).
struct MeridianClassification {
  PointContact contact;
  std::uint8_t region;
  double depth_mm;
  MeridianDirection escape;
};
[[nodiscard]] MeridianClassification classify_meridian(const ToolBsp& tool, MeridianPoint point);

}  // namespace stencil::geometry
