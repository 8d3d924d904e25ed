// Which region of the tool's BSP a whole box of the meridian plane is in, decided once for the box
// instead of once per point: the query uses it to settle a leaf of the part's tree in one walk.
#pragma once

#include <cstdint>

#include "firmware/core/geometry/tool_bsp.hpp"

namespace stencil::geometry {

// A rectangle of the meridian half-plane (mm): r_low >= 0, low <= high.
struct MeridianBox {
  double r_low_mm;
  double r_high_mm;
  double z_low_mm;
  double z_high_mm;
};

enum class BoxCover : std::uint8_t {
  Outside,          // every point of the box is outside the tool
  Region,           // every point of the box reaches region `region` (inside the tool or on its surface)
  RegionOrOutside,  // the box straddles the boundary surface of region `region` and nothing else:
                    // a point reaches the region exactly when its interior distance to the region's
                    // surface is at least -kSurfaceTolerance_mm, and is outside the tool otherwise
  SplitAtZ,         // the box straddles a partition plane z = split_z_mm of the tree and nothing
                    // else there: a point with z - split_z_mm < 0 is settled as `below` says, any
                    // other as `above` says (each Outside, Region or RegionOrOutside)
  Mixed,            // the box straddles other tests of the tree (or the tree or box is unusable):
                    // ask per point
};

// One side's answer: Outside, Region or RegionOrOutside, as above.
struct BoxPart {
  BoxCover cover;
  std::uint8_t region;       // valid for Region and RegionOrOutside
  double deepest_bound_mm;   // no point is deeper than this inside the region's surface
};

struct BoxClassification {
  BoxCover cover;
  std::uint8_t region;       // valid for Region and RegionOrOutside
  double deepest_bound_mm;   // Region, RegionOrOutside: no point of the box is deeper than this
                             // inside the region's surface; SplitAtZ: the larger of the two sides'
  double split_z_mm;         // SplitAtZ only
  BoxPart below;             // SplitAtZ only
  BoxPart above;             // SplitAtZ only
};

// Walks the tree once with the range each node's test takes over the box. The answer holds for
// every point classify_meridian would be given from inside the box: the ranges come from the same
// arithmetic at the box's nearest and farthest corners, and that arithmetic is monotonic, so no
// point's rounded value falls outside its box's range. Allocation-free, at most node_count steps.
[[nodiscard]] BoxClassification classify_meridian_box(const ToolBsp& tool, const MeridianBox& box);

// No point of `box` is deeper than this inside the surface of region `region` (a region index of
// the tree): the deepest_bound_mm classify_meridian_box gives a box it settles in that region, by
// the same arithmetic. NaN when the surface's numbers are.
[[nodiscard]] double region_deepest_bound(const ToolBsp& tool, std::uint8_t region, const MeridianBox& box);

// Every point of `box` is between these depths inside the surface of region `region`, as
// classify_meridian rounds it: region_deepest_bound's number and the shallowest counterpart, by the
// same arithmetic. A box settled in that region (Region or RegionOrOutside) whose shallowest depth
// is beyond kSurfaceTolerance_mm has every point in the region and penetrating. NaN when the
// surface's numbers are.
struct DepthRange {
  double shallowest_mm;
  double deepest_mm;
};
[[nodiscard]] DepthRange region_depth_range(const ToolBsp& tool, std::uint8_t region, const MeridianBox& box);

// The meridian box that holds every point of the axis-aligned world box [low, high] as seen from
// an upright tool (axis +z) with its tip at tip_mm, computed as the query computes each point's
// r and z (local = point - tip, r = sqrt(x^2 + y^2)).
[[nodiscard]] MeridianBox upright_meridian_box(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& low,
                                               const Eigen::Vector3d& high);

}  // namespace stencil::geometry
