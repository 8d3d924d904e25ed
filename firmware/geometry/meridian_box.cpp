// Interval walk of the tool's BSP over a meridian box.
#include "firmware/geometry/meridian_box.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::geometry {
namespace {

struct Range {
  double low;
  double high;
};

enum class Answer : std::uint8_t { True, False, Unknown };

// The range of the surface's natural function over the box. For a plane or a cylinder f is
// monotonic in z or r; for a sphere or torus it is a distance from a centre, least at the box point
// nearest the centre (the centre clamped into the box) and greatest at a corner.
Range function_range(const ImplicitSurface& surface, const MeridianBox& box) {
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

Range interior_range(const ImplicitSurface& surface, const MeridianBox& box) {
  const Range f = function_range(surface, box);
  // interior_distance is -f on a Below surface and f on an Above one; negation is exact.
  return surface.solid_side == SolidSide::Below ? Range{-f.high, -f.low} : f;
}

bool is_nan(const Range& range) { return std::isnan(range.low) || std::isnan(range.high); }

// The node's test over the whole box, as classify_meridian's evaluate decides it per point.
Answer evaluate(const ToolBsp& tool, const BspNode& node, const MeridianBox& box) {
  const ImplicitSurface& a = tool.surfaces[node.surface_a];
  switch (node.test) {
    case NodeTest::InsideBoundary: {  // -tolerance <= interior distance
      const Range inside = interior_range(a, box);
      if (is_nan(inside)) {
        return Answer::Unknown;
      }
      return -kSurfaceTolerance_mm <= inside.low ? Answer::True
             : -kSurfaceTolerance_mm <= inside.high ? Answer::Unknown
                                                    : Answer::False;
    }
    case NodeTest::BelowPartition: {  // f < 0
      const Range f = function_range(a, box);
      if (is_nan(f)) {
        return Answer::Unknown;
      }
      return f.high < 0.0 ? Answer::True : f.low < 0.0 ? Answer::Unknown : Answer::False;
    }
    case NodeTest::NearerThan: {  // interior distance to a <= interior distance to b
      const Range left = interior_range(a, box);
      const Range right = interior_range(tool.surfaces[node.surface_b], box);
      if (is_nan(left) || is_nan(right)) {
        return Answer::Unknown;
      }
      return left.high <= right.low ? Answer::True : left.low <= right.high ? Answer::Unknown : Answer::False;
    }
  }
  return Answer::Unknown;
}

constexpr BoxClassification kMixed{BoxCover::Mixed, 0, 0.0};

}  // namespace

BoxClassification classify_meridian_box(const ToolBsp& tool, const MeridianBox& box) {
  // Anything classify_meridian would call a fault is left to it, point by point.
  if (tool.node_count == 0 || tool.node_count > kMaxToolNodes || tool.surface_count > kMaxToolSurfaces ||
      tool.region_count > kMaxToolRegions || !std::isfinite(box.r_low_mm) || !std::isfinite(box.r_high_mm) ||
      !std::isfinite(box.z_low_mm) || !std::isfinite(box.z_high_mm) || !(box.r_low_mm >= 0.0) ||
      !(box.r_low_mm <= box.r_high_mm) || !(box.z_low_mm <= box.z_high_mm)) {
    return kMixed;
  }
  // A box across a boundary test whose false side is the outside of the tool is still settled if
  // its true side leads, for the whole box, to the region of that same surface: the per-point test
  // is then the region's own depth against the tolerance (see RegionOrOutside).
  bool straddles_boundary = false;
  std::uint8_t boundary_surface = 0;
  std::size_t node_index = 0;
  for (std::size_t step = 0; step < tool.node_count; ++step) {
    const BspNode& node = tool.nodes[node_index];
    if (node.surface_a >= tool.surface_count ||
        (node.test == NodeTest::NearerThan && node.surface_b >= tool.surface_count)) {
      return kMixed;
    }
    Answer answer = evaluate(tool, node, box);
    if (answer == Answer::Unknown) {
      if (straddles_boundary || node.test != NodeTest::InsideBoundary ||
          node.when_false.kind != BspLink::Kind::Outside) {
        return kMixed;
      }
      straddles_boundary = true;
      boundary_surface = node.surface_a;
      answer = Answer::True;
    }
    const BspLink link = answer == Answer::True ? node.when_true : node.when_false;
    switch (link.kind) {
      case BspLink::Kind::Outside:
        return straddles_boundary ? kMixed : BoxClassification{BoxCover::Outside, 0, 0.0};
      case BspLink::Kind::Region:
        if (link.index >= tool.region_count || tool.regions[link.index].surface >= tool.surface_count) {
          return kMixed;
        }
        {
          const double deepest = interior_range(tool.surfaces[tool.regions[link.index].surface], box).high;
          if (!straddles_boundary) {
            return {BoxCover::Region, link.index, deepest};
          }
          return tool.regions[link.index].surface == boundary_surface
                     ? BoxClassification{BoxCover::RegionOrOutside, link.index, deepest}
                     : kMixed;
        }
      case BspLink::Kind::Node:
        if (link.index <= node_index || link.index >= tool.node_count) {
          return kMixed;
        }
        node_index = link.index;
        break;
      default:
        return kMixed;
    }
  }
  return kMixed;
}

MeridianBox upright_meridian_box(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& low,
                                 const Eigen::Vector3d& high) {
  // Subtraction, squaring, addition and sqrt are each monotonic, so the nearest and farthest
  // points of the box's footprint bound every point's r as the query rounds it.
  const double x_low = low.x() - tip_mm.x();
  const double x_high = high.x() - tip_mm.x();
  const double y_low = low.y() - tip_mm.y();
  const double y_high = high.y() - tip_mm.y();
  const double near_x = std::min(std::max(0.0, x_low), x_high);
  const double near_y = std::min(std::max(0.0, y_low), y_high);
  const double far_x = std::max(x_low * x_low, x_high * x_high);
  const double far_y = std::max(y_low * y_low, y_high * y_high);
  return {std::sqrt(near_x * near_x + near_y * near_y), std::sqrt(far_x + far_y), low.z() - tip_mm.z(),
          high.z() - tip_mm.z()};
}

}  // namespace stencil::geometry
