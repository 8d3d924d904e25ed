// Walks the tool's BSP tree: which region a point is in, how deep, and which way it escapes.
#include "firmware/core/geometry/tool_bsp.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace stencil::geometry {
namespace {

// Below this radius the radial direction of a point is numerically meaningless.
constexpr double kOnAxisRadius_mm = 1e-12;

enum class Branch : std::uint8_t { True, False, Invalid };

// A NaN anywhere (in the point or in the tree's numbers) is a fault, never a quiet "outside".
Branch evaluate(const ToolBsp& tool, const BspNode& node, MeridianPoint point) {
  const ImplicitSurface& a = tool.surfaces[node.surface_a];
  double left = 0.0;
  double right = 0.0;
  switch (node.test) {
    case NodeTest::InsideBoundary:
      left = -kSurfaceTolerance_mm;
      right = interior_distance(a, point);
      break;
    case NodeTest::BelowPartition:
      left = surface_function(a, point);
      right = 0.0;
      if (std::isnan(left)) {
        return Branch::Invalid;
      }
      return left < right ? Branch::True : Branch::False;
    case NodeTest::NearerThan:
      left = interior_distance(a, point);
      right = interior_distance(tool.surfaces[node.surface_b], point);
      break;
    default:
      return Branch::Invalid;
  }
  if (std::isnan(left) || std::isnan(right)) {
    return Branch::Invalid;
  }
  return left <= right ? Branch::True : Branch::False;
}

MeridianClassification bad_tree() {
  return {PointContact::BadTree, 0, 0.0, {0.0, 0.0}};
}

// A unit vector perpendicular to the axis, used as "radial" for points on the axis.
Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& unit_axis) {
  const Eigen::Vector3d helper =
      std::abs(unit_axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return unit_axis.cross(helper).normalized();
}

}  // namespace

MeridianClassification classify_meridian(const ToolBsp& tool, MeridianPoint point) {
  if (tool.node_count == 0 || tool.node_count > kMaxToolNodes || tool.surface_count > kMaxToolSurfaces ||
      tool.region_count > kMaxToolRegions || !std::isfinite(point.r_mm) || !std::isfinite(point.z_mm)) {
    return bad_tree();
  }
  std::size_t node_index = 0;
  // Links only point forward in a checked tree, so node_count steps always reach a leaf; the bound
  // keeps a damaged tree from looping.
  for (std::size_t step = 0; step < tool.node_count; ++step) {
    const BspNode& node = tool.nodes[node_index];
    if (node.surface_a >= tool.surface_count ||
        (node.test == NodeTest::NearerThan && node.surface_b >= tool.surface_count)) {
      return bad_tree();
    }
    const Branch branch = evaluate(tool, node, point);
    if (branch == Branch::Invalid) {
      return bad_tree();
    }
    const BspLink link = branch == Branch::True ? node.when_true : node.when_false;
    switch (link.kind) {
      case BspLink::Kind::Outside:
        return {PointContact::Outside, 0, 0.0, {0.0, 0.0}};
      case BspLink::Kind::Region: {
        if (link.index >= tool.region_count || tool.regions[link.index].surface >= tool.surface_count) {
          return bad_tree();
        }
        const ImplicitSurface& surface = tool.surfaces[tool.regions[link.index].surface];
        const double depth = interior_distance(surface, point);
        const MeridianDirection escape = escape_direction(surface, point);
        if (!std::isfinite(depth) || !std::isfinite(escape.radial) || !std::isfinite(escape.axial)) {
          return bad_tree();
        }
        if (depth > kSurfaceTolerance_mm) {
          return {PointContact::Penetrating, link.index, depth, escape};
        }
        return {PointContact::Touching, link.index, 0.0, escape};
      }
      case BspLink::Kind::Node:
        // Forward only: a backward link could reach a region by a path the tree never meant.
        if (link.index <= node_index || link.index >= tool.node_count) {
          return bad_tree();
        }
        node_index = link.index;
        break;
      default:
        return bad_tree();
    }
  }
  return bad_tree();
}

PointClassification classify_at_pose(const ToolBsp& tool, const Eigen::Vector3d& tip_mm,
                                      const Eigen::Vector3d& unit_axis, const Eigen::Vector3d& point_mm) {
  const Eigen::Vector3d offset = point_mm - tip_mm;
  const double z = offset.dot(unit_axis);
  const Eigen::Vector3d radial_offset = offset - z * unit_axis;
  const double r = radial_offset.norm();
  const MeridianClassification meridian = classify_meridian(tool, {r, z});
  if (meridian.contact == PointContact::Outside || meridian.contact == PointContact::BadTree) {
    return {meridian.contact, meridian.region, 0.0, Eigen::Vector3d::Zero()};
  }
  const Eigen::Vector3d radial =
      r > kOnAxisRadius_mm ? Eigen::Vector3d(radial_offset / r) : any_perpendicular(unit_axis);
  const Eigen::Vector3d escape = meridian.escape.radial * radial + meridian.escape.axial * unit_axis;
  return {meridian.contact, meridian.region, meridian.depth_mm, escape};
}

PointClassification classify_in_tool_frame(const ToolBsp& tool, const Eigen::Vector3d& point_mm) {
  return classify_at_pose(tool, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), point_mm);
}

}  // namespace stencil::geometry
