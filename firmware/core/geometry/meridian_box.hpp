// Which region of the tool's BSP a whole box of the meridian plane is in, decided once for the box
// instead of once per point: the query uses it to settle a leaf of the part's tree in one walk.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "firmware/core/geometry/implicit_surface.hpp"
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

// Inline: the walk of the points' tree asks these of most nodes it meets.

namespace meridian_box_detail {

struct Range {
  double low;
  double high;
};

// The range of the surface's natural function over the box. For a plane or a cylinder f is
// monotonic in z or r; for a sphere or torus it is a distance from a centre, least at the box point
// nearest the centre (the centre clamped into the box) and greatest at a corner.
inline Range function_range(const ImplicitSurface& surface, const MeridianBox& box) {
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
    case SurfaceKind::Cylinder:
      return {surface_function(surface, {box.r_low_mm, box.z_low_mm}),
              surface_function(surface, {box.r_high_mm, box.z_high_mm})};
    case SurfaceKind::Sphere:
    case SurfaceKind::Torus: {
      const double centre_r = surface.kind == SurfaceKind::Torus ? surface.center_r_mm : 0.0;
      const double near_r = std::min(std::max(centre_r, box.r_low_mm), box.r_high_mm);
      const double near_z = std::min(std::max(surface.center_z_mm, box.z_low_mm), box.z_high_mm);
      // The farthest corner pairs the larger squared offset in r with the larger one in z (the
      // sum separates, and rounded addition and sqrt are monotonic): every corner's value, one sqrt.
      const double dr_low = box.r_low_mm - centre_r, dr_high = box.r_high_mm - centre_r;
      const double dz_low = box.z_low_mm - surface.center_z_mm, dz_high = box.z_high_mm - surface.center_z_mm;
      const double far = std::sqrt(std::max(dr_low * dr_low, dr_high * dr_high) +
                                   std::max(dz_low * dz_low, dz_high * dz_high)) -
                         surface.radius_mm;
      return {surface_function(surface, {near_r, near_z}), far};
    }
  }
  return {std::nan(""), std::nan("")};
}

inline Range interior_range(const ImplicitSurface& surface, const MeridianBox& box) {
  const Range f = function_range(surface, box);
  // interior_distance is -f on a Below surface and f on an Above one; negation is exact.
  return surface.solid_side == SolidSide::Below ? Range{-f.high, -f.low} : f;
}

}  // namespace meridian_box_detail

inline DepthRange region_depth_range(const ToolBsp& tool, std::uint8_t region, const MeridianBox& box) {
  const meridian_box_detail::Range range =
      meridian_box_detail::interior_range(tool.surfaces[tool.regions[region].surface], box);
  return {range.low, range.high};
}

namespace meridian_box_detail {

// The squared distances from the upright axis through the tip of the nearest and the farthest
// point of the box's footprint.
struct Footprint {
  double near_squared;
  double far_squared;
};
[[gnu::always_inline]] inline Footprint footprint(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& low,
                                                  const Eigen::Vector3d& high) {
  const double x_low = low.x() - tip_mm.x();
  const double x_high = high.x() - tip_mm.x();
  const double y_low = low.y() - tip_mm.y();
  const double y_high = high.y() - tip_mm.y();
  const double near_x = std::min(std::max(0.0, x_low), x_high);
  const double near_y = std::min(std::max(0.0, y_low), y_high);
  const double far_x = std::max(x_low * x_low, x_high * x_high);
  const double far_y = std::max(y_low * y_low, y_high * y_high);
  return {near_x * near_x + near_y * near_y, far_x + far_y};
}

}  // namespace meridian_box_detail

inline MeridianBox upright_meridian_box(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& low,
                                        const Eigen::Vector3d& high) {
  // Subtraction, squaring, addition and sqrt are each monotonic, so the nearest and farthest
  // points of the box's footprint bound every point's r as the query rounds it.
  const meridian_box_detail::Footprint f = meridian_box_detail::footprint(tip_mm, low, high);
  return {std::sqrt(f.near_squared), std::sqrt(f.far_squared), low.z() - tip_mm.z(), high.z() - tip_mm.z()};
}

// Between which depths a node's box lies, told without a sqrt where the rounding cannot matter: the
// walk of the points' tree asks it of every node under a settled one, and most of them are told
// apart here, without the two sqrts in a chain that region_depth_range takes for a ball or a side.
enum class DepthSpan : std::uint8_t {
  Shallower,  // region_depth_range(tool, region, upright_meridian_box(tip, low, high)) has deepest_mm < shallow_mm
  Between,    // ... has deepest_mm >= shallow_mm and shallowest_mm <= deep_mm
  Unsure,     // ask region_depth_range: too near either threshold, wholly deeper than deep_mm, a
              // torus, a solid above its surface, a threshold past half the radius, or a radius that
              // is not finite. An answer is given only where region_depth_range's numbers give the
              // same one, numbers that are not finite included (a centre at infinity: shallow).
};

// For a plane, region_depth_range's own arithmetic (it needs no radius). For a ball centred on the
// axis or a side, the squared distance from the centre (axis) of the box's nearest and farthest
// points against the squared distance at which the depth R - d reaches each threshold, with a
// relative margin of 1e-9: the sqrt-based depths round within a few units of 1e-16 of these, so
// an answer given here is the one region_depth_range's numbers give. Set up once for a region and
// a tip (the walk meets one region in most subtrees), then asked of many boxes.
class UprightDepthSpan {
 public:
  UprightDepthSpan(const ToolBsp& tool, std::uint8_t region, const Eigen::Vector3d& tip_mm, double shallow_mm,
                   double deep_mm)
      : surface_(&tool.surfaces[tool.regions[region].surface]),
        tip_mm_(tip_mm),
        shallow_mm_(shallow_mm),
        deep_mm_(deep_mm),
        skip_above_(0.0),
        skip_below_(0.0),
        deep_above_(0.0),
        kind_(Kind::Unsure),
        region_(region) {
    const double skip_reach = surface_->radius_mm - shallow_mm;  // nearer than this: deeper than shallow_mm
    const double deep_reach = surface_->radius_mm - deep_mm;     // farther than this: not deeper than deep_mm
    constexpr double kMargin = 1e-9;
    if (surface_->kind == SurfaceKind::PlaneZ) {
      kind_ = Kind::Plane;
    } else if ((surface_->kind == SurfaceKind::Sphere || surface_->kind == SurfaceKind::Cylinder) &&
               surface_->solid_side == SolidSide::Below && deep_reach > 0.5 * surface_->radius_mm &&
               skip_reach > 0.5 * surface_->radius_mm) {
      kind_ = surface_->kind == SurfaceKind::Sphere ? Kind::Ball : Kind::Side;
      skip_above_ = skip_reach * skip_reach * (1.0 + kMargin);
      skip_below_ = skip_reach * skip_reach * (1.0 - kMargin);
      deep_above_ = deep_reach * deep_reach * (1.0 + kMargin);
    }
  }

  std::uint8_t region() const { return region_; }

  [[gnu::always_inline]] DepthSpan operator()(const Eigen::Vector3d& low, const Eigen::Vector3d& high) const {
    if (kind_ == Kind::Unsure) {
      return DepthSpan::Unsure;
    }
    const double z_low = low.z() - tip_mm_.z();
    const double z_high = high.z() - tip_mm_.z();
    if (kind_ == Kind::Plane) {
      const meridian_box_detail::Range range = meridian_box_detail::interior_range(*surface_, {0.0, 0.0, z_low, z_high});
      if (range.high < shallow_mm_) {
        return DepthSpan::Shallower;
      }
      return range.high >= shallow_mm_ && range.low <= deep_mm_ ? DepthSpan::Between : DepthSpan::Unsure;
    }
    const Reach reach = reach_of(low, high);
    if (reach.near_squared > skip_above_) {
      return DepthSpan::Shallower;
    }
    return reach.near_squared < skip_below_ && reach.far_squared > deep_above_ ? DepthSpan::Between : DepthSpan::Unsure;
  }

  // Of a box told Between, a bound no less than region_depth_range's deepest_mm, for the walk's
  // question whether a leaf's point may be the deepest found: the same number for a plane; for a
  // ball or a side the nearest point's depth with its distance shortened by 1e-12 of itself, past
  // the rounding of either way of computing it.
  [[nodiscard]] double deepest_bound(const Eigen::Vector3d& low, const Eigen::Vector3d& high) const {
    if (kind_ == Kind::Plane) {
      return meridian_box_detail::interior_range(*surface_, {0.0, 0.0, low.z() - tip_mm_.z(), high.z() - tip_mm_.z()}).high;
    }
    if (kind_ == Kind::Unsure) {
      return std::numeric_limits<double>::infinity();
    }
    return surface_->radius_mm - std::sqrt(reach_of(low, high).near_squared) * (1.0 - 1e-12);
  }

 private:
  enum class Kind : std::uint8_t { Unsure, Plane, Ball, Side };

  // The squared distance of the box's nearest and farthest points from the ball's centre, or
  // from the axis for a side.
  struct Reach {
    double near_squared;
    double far_squared;
  };
  [[gnu::always_inline]] Reach reach_of(const Eigen::Vector3d& low, const Eigen::Vector3d& high) const {
    const meridian_box_detail::Footprint f = meridian_box_detail::footprint(tip_mm_, low, high);
    Reach reach{f.near_squared, f.far_squared};
    if (kind_ == Kind::Ball) {
      const double centre_z = surface_->center_z_mm;
      const double z_low = low.z() - tip_mm_.z();
      const double z_high = high.z() - tip_mm_.z();
      const double near_dz = std::min(std::max(centre_z, z_low), z_high) - centre_z;
      const double dz_low = z_low - centre_z;
      const double dz_high = z_high - centre_z;
      reach.near_squared += near_dz * near_dz;
      reach.far_squared += std::max(dz_low * dz_low, dz_high * dz_high);
    }
    return reach;
  }

  const ImplicitSurface* surface_;
  Eigen::Vector3d tip_mm_;
  double shallow_mm_;
  double deep_mm_;
  double skip_above_;  // squared distances, margins included
  double skip_below_;
  double deep_above_;
  Kind kind_;
  std::uint8_t region_;
};

}  // namespace stencil::geometry
