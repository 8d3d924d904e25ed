// One leaf of the part's tree against the upright tool, all its points at once: depth, escape
// direction, force and torque, over fixed-size Eigen arrays so each instruction serves several
// points. This is where the query spends its time in deep contact.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "firmware/geometry/meridian_box.hpp"
#include "firmware/geometry/tool_bsp.hpp"
#include "firmware/tables/part_tables.hpp"
#include "firmware/tables/table_format.hpp"

namespace stencil::engine {

using LeafLanes = Eigen::Array<double, tables::kMaxLeafPoints, 1>;

// Below this length a point's normal and the tool's escape direction cancel: the point gives no
// force direction (the same threshold for the per-point path of the query and the lanes).
inline constexpr double kNoDirection = 1e-12;

struct LeafContacts {
  std::uint32_t first;   // table index of the leaf's first point
  std::uint32_t count;   // its points (1 to 32); lanes past count repeat the last point
  LeafLanes x, y, z;     // world mm
  LeafLanes nx, ny, nz;  // the points' normals
  LeafLanes depth;       // inside the tool's surface, mm: penetrating beyond kSurfaceTolerance_mm;
                         // 0 for points outside the tool or on its surface, and past count
  LeafLanes ex, ey, ez;  // escape direction in world frame; 0 for points outside the tool
  std::array<bool, tables::kMaxLeafPoints> in_tool;  // touching or penetrating; false past count
};

// Widens the leaf's points and normals into the lanes. count must be 1 to kMaxLeafPoints and the
// run inside the tables (the walk checks it).
void load_leaf(const tables::PartTables& part, std::uint32_t first, std::uint32_t count, LeafContacts& leaf);

// Every point of the leaf lies in region `region` of the upright tool with its tip at tip_mm or,
// when `or_outside`, either in it or outside the tool (geometry::classify_meridian_box's Region
// and RegionOrOutside): depth and escape from that region's surface, with no walk of the tool
// tree. False when a result is not finite (a damaged tool tree): a fault.
[[nodiscard]] bool region_leaf_contacts(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside,
                                        const Eigen::Vector3d& tip_mm, LeafContacts& leaf);

// The leaf straddles a plane z = split_z_mm of the tool tree (geometry::classify_meridian_box's
// SplitAtZ): each side's part settled as above, and each point takes its own side's numbers. False
// as above.
[[nodiscard]] bool split_leaf_contacts(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover,
                                       const Eigen::Vector3d& tip_mm, LeafContacts& leaf);

// The leaf straddles the tool's tests: each point through the tool tree (classify_meridian), the
// arithmetic before and after it still over the lanes. False on a damaged tree.
[[nodiscard]] bool mixed_leaf_contacts(const geometry::ToolBsp& tool, const Eigen::Vector3d& tip_mm,
                                       LeafContacts& leaf);

// Each point's f_i = k_world * d_i along normalize(normal - escape) and its torque about `centre`
// (zero for a point whose normal and escape direction cancel, or that is outside the tool).
struct LeafForces {
  LeafLanes fx, fy, fz;
  LeafLanes tx, ty, tz;
};
void leaf_forces(const LeafContacts& leaf, double k_world, const Eigen::Vector3d& centre, LeafForces& forces);

}  // namespace stencil::engine
