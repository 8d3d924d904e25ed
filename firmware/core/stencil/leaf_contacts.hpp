// One leaf of the part's tree against the upright tool, all its points at once: depth, escape
// direction, force and torque, lane by lane in single precision so each instruction serves eight
// points, with every decision (which points penetrate, which touch, which is deepest and how deep)
// settled in double precision. This is where the query spends its time in deep contact.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "firmware/core/geometry/meridian_box.hpp"
#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::engine {

// Why single precision: the points are stored as floats, a float lane is half as wide as a double
// and its square root and division several times cheaper, and the deep-contact cycle at 1e6 points
// is bound by exactly that arithmetic. A float depth is within a bound of the double one that
// grows with the leaf's size (LeafContacts::band_mm); every point whose float depth lies within
// that band of the tool's surface, and every point that may be the deepest, is computed again in
// double precision, so the count, the touched set, the legality and the deepest depth are those of
// the double-precision classification. Only the force and torque sums carry the float rounding
// (relative error about 1e-6, far below anything the operator can feel).
using LeafLanes = std::array<float, tables::kMaxLeafPoints>;
using LaneMask = std::uint64_t;  // bit i for lane i
static_assert(tables::kMaxLeafPoints <= 64, "a lane mask holds every lane of a leaf");

// Below this length a point's normal and the tool's escape direction cancel: the point gives no
// force direction (the same threshold for the per-point path of the query and the lanes).
inline constexpr double kNoDirection = 1e-12;

struct LeafContacts {
  std::uint32_t first;                // table index of the leaf's first point
  std::uint32_t count;                // its points (1 to kMaxLeafPoints); lanes past count repeat the last point
  const tables::PackedPoint* points;  // the leaf's points in the tables, for the double-precision checks
  Eigen::Vector3d tip_mm;             // the tool's tip the offsets are taken from
  float tip_high[3];                  // the tip split for float offsets: (p - high) - low (see bind_leaf)
  float tip_low[3];
  float magnitude_mm;                 // no lane's |x| + |y| + |z| is larger (a bound from the block's sphere)
  alignas(32) LeafLanes x;            // offset of each point from the tip, world mm
  alignas(32) LeafLanes y;
  alignas(32) LeafLanes z;
  const tables::LeafBlock* normals;  // the leaf's block, whose nx, ny, nz are the points' normals
  alignas(32) LeafLanes depth;  // > 0 exactly in the lanes that penetrate beyond kSurfaceTolerance_mm
                                // (the double-precision verdict); 0 elsewhere and past count
  alignas(32) LeafLanes ex;     // escape direction in world frame; 0 for points outside the tool
  alignas(32) LeafLanes ey;
  alignas(32) LeafLanes ez;
  LaneMask in_tool;            // lanes touching or penetrating; none past count
  LaneMask penetrating_lanes;  // lanes with depth > 0
  std::uint32_t penetrating;   // how many
  double max_depth_mm;        // the deepest lane's depth in double precision; 0 when none penetrates
  std::uint32_t deepest_lane; // the first lane at max_depth_mm (valid when penetrating > 0)
};

// The tool's tip, and split for the lanes' offsets: (p - high) - low is p's offset to within a
// rounding of its own size, however far the part is from the origin (once per pose).
struct LeafTip {
  Eigen::Vector3d mm;
  float high[3];
  float low[3];
};
[[nodiscard]] LeafTip leaf_tip(const Eigen::Vector3d& tip_mm);

// Binds the leaf to its packed block and the tip: its run of points, the block for its points and
// normals (it must outlive the leaf's use) and the bound of its offsets from its sphere, with no
// lane loaded: region_leaf_force and split_leaf_force compute their lanes from the block as they
// go. The block's count must be 1 to kMaxLeafPoints and its run inside the tables (the loader
// checks it, the walk again).
void bind_leaf(const tables::PartTables& part, const tables::LeafBlock& block, const LeafTip& tip, LeafContacts& leaf);

// Loads a bound leaf's points into the lanes x, y, z, as offsets from its tip: what every other
// function of a leaf reads.
void load_lanes(LeafContacts& leaf);

// bind_leaf, then load_lanes.
void load_leaf(const tables::PartTables& part, const tables::LeafBlock& block, const Eigen::Vector3d& tip_mm,
               LeafContacts& leaf);

// Every point of the leaf lies in region `region` of the upright tool or, when `or_outside`,
// either in it or outside the tool (geometry::classify_meridian_box's Region and RegionOrOutside):
// depth and escape from that region's surface, with no walk of the tool tree. False when a result
// is not finite (a damaged tool tree): a fault.
[[nodiscard]] bool region_leaf_contacts(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside,
                                        LeafContacts& leaf);

// The leaf straddles a plane z = split_z_mm of the tool tree (geometry::classify_meridian_box's
// SplitAtZ): each side's part settled as above, and each point takes its own side's numbers. False
// as above.
[[nodiscard]] bool split_leaf_contacts(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover,
                                       LeafContacts& leaf);

// The leaf straddles the tool's tests: each point through the tool tree (classify_meridian, in
// double precision), the arithmetic after it still over the lanes. False on a damaged tree.
[[nodiscard]] bool mixed_leaf_contacts(const geometry::ToolBsp& tool, LeafContacts& leaf);

// The sum over the leaf of each point's f_i = k_world * d_i along normalize(normal - escape), and
// of its torque r_i x f_i about the point `centre_height_mm` up the axis from the tip (zero for a
// point whose normal and escape direction cancel, or that does not penetrate).
struct LeafForceSums {
  Eigen::Vector3d force;
  Eigen::Vector3d torque;
};
[[nodiscard]] LeafForceSums leaf_forces(const LeafContacts& leaf, double k_world, double centre_height_mm);

// region_leaf_contacts and leaf_forces in one pass, for the query's force: the leaf (bound by
// bind_leaf, its lanes computed here as load_lanes would) lies in region `region` of the upright tool, or in it or outside (`or_outside`). The
// same numbers, bit for bit, with nothing stored between the steps (with AVX2; without it, the two
// steps themselves, the leaf settled in place). The deepest lane is searched only when
// `find_deepest` (the caller knows no lane can beat what it has otherwise); max_depth_mm is 0 when
// it is not. False on a non-finite result.
struct RegionLeafForce {
  std::uint32_t penetrating;   // lanes deeper than the tolerance (double-precision verdict)
  double max_depth_mm;         // the deepest lane's depth, when searched and some lane penetrates
  std::uint32_t deepest_lane;  // the first lane at max_depth_mm
  LeafForceSums sums;
};
[[nodiscard]] bool region_leaf_force(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside,
                                     bool find_deepest, double k_world, double centre_height_mm,
                                     LeafContacts& leaf, RegionLeafForce& out);

// The deepest lane of a leaf (bound by bind_leaf) wholly in region `region`, as
// region_leaf_contacts finds it, and how many lanes penetrate: region_leaf_force's depths with
// find_deepest, without the directions and the force (sums zero). Groups of lanes
// (tables::kLeafGroupPoints) whose every point is shallower than floor_mm by the group's own bound
// (its centroid's depth plus its radius) may be left out, as if none of their lanes penetrated:
// for a search that only wants a point deeper than floor_mm, or as deep and earlier. -infinity
// leaves none out. False on a non-finite result.
[[nodiscard]] bool region_leaf_deepest(const geometry::ToolBsp& tool, std::uint8_t region, double floor_mm,
                                       LeafContacts& leaf, RegionLeafForce& out);

// split_leaf_contacts and leaf_forces in one pass, for the query's force: the leaf (bound by
// bind_leaf) straddles the partition plane of `cover` (SplitAtZ), each lane settled by its own
// side's region. The same numbers, bit for bit, as the two steps, as region_leaf_force gives.
[[nodiscard]] bool split_leaf_force(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover,
                                    bool find_deepest, double k_world, double centre_height_mm, LeafContacts& leaf,
                                    RegionLeafForce& out);

// A leaf wholly deeper than the tolerance, from its moments: its points' count times the region's
// depth at their centroid, along v = mean normal - the region's escape direction there,
// normalised; the torque of that force at the centroid (its line of action stays within the leaf).
// About the centroid the first order of the depth's and the direction's change over the leaf
// cancels, so this differs from the sum of the points' forces by the second order in the points'
// spread sigma (taken as half the radius that holds them), relatively about
//   sigma^2 k / 2d  +  sigma^2 k / (d |v|)  +  sigma^2 k^2 / (2 |v|^2),
// where d is the depth at the centroid and k how fast the escape direction turns there (1 / the
// distance to the axis, or to a sphere's or a torus tube's centre; 0 for a plane): the depth's
// curvature, its change against the direction's, and the direction's own curvature, the last two
// the larger where the normal and the escape nearly cancel (|v| small), since normalize(v) turns
// with 1 / |v|. Normals that differ (1 - |mean normal|) turn it by about 2 (1 - |mean normal|) / |v|.
// A leaf is settled so only where each estimate is at most kMomentError; otherwise each of its
// groups of kLeafGroupPoints lanes (LeafBlock's group moments: a quarter of the points, about half
// the radius) is tried the same way, and the leaf is settled from its groups if every one of them
// is; failing that, it is left to its points (`settled` false). The query asks this only of a leaf
// whose box says every point is deeper than the tolerance in one region (so the count and the
// deepest depth stay exact); `surface` is that region's. Measured at 1e6 points (stencil-bench's
// deep-corner pose): 67 leaves settled whole, 25 from their groups and 8 left to their points; the
// query 281,069 instructions against 300,592 with the leaves' own moments alone (when measured,
// before the rest of that change: 241,345 with it all, 331,823 with every deep leaf visited).
inline constexpr double kMomentError = 0.05;
struct LeafMomentForce {
  bool settled;
  Eigen::Vector3d force;
  Eigen::Vector3d torque;
};
[[nodiscard]] LeafMomentForce leaf_moment_force(const geometry::ImplicitSurface& surface,
                                                const tables::LeafBlock& block, const Eigen::Vector3d& tip_mm,
                                                const Eigen::Vector3d& centre, double k_world);


// The deepest any point of the leaf can be inside `surface`: its sphere's centre's depth plus its
// radius (the depth is a distance, so it changes no faster than the point moves), with a margin
// for the rounding of that one depth.
[[nodiscard]] double leaf_deepest_bound(const geometry::ImplicitSurface& surface, const tables::LeafBlock& block,
                                        const Eigen::Vector3d& tip_mm);

}  // namespace stencil::engine
