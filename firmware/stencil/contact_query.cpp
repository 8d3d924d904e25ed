// The query: the tool's 14-DOP against the points' tree, then each nearby point through the tool BSP.
#include "firmware/stencil/contact_query.hpp"

#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "firmware/geometry/kdop14.hpp"
#include "firmware/geometry/tool_bound.hpp"
#include "firmware/geometry/tool_bsp_builder.hpp"
#include "firmware/geometry/upright_tool.hpp"

namespace stencil::engine {
namespace {

enum class Walk : std::uint8_t { Finished, Stopped, BadTree };

bool pose_is_usable(const ToolPose& pose) {
  return pose.tip_mm.allFinite() && pose.axis.allFinite() && std::abs(pose.axis.squaredNorm() - 1.0) < 1e-9;
}

bool overlaps_node(const geometry::Kdop14& volume, const tables::BvhNode& node) {
  for (std::size_t slab = 0; slab < geometry::kKdopSlabCount; ++slab) {
    if (volume.min[slab] > node.dop_max[slab] || node.dop_min[slab] > volume.max[slab]) {
      return false;
    }
  }
  return true;
}

// Calls visit(point index, classification) for every point that is in the tool or on its surface
// (points outside are skipped), until visit returns false. Leaves are culled by the tool's 14-DOP
// and, for the upright tool of the 3-axis mill, by its outline (the envelope's DOP is loose around a
// ball's end); points by the outline before the BSP. Iterative, with a fixed stack as deep as the
// loader allows trees to be.
template <typename Visit>
Walk walk_points_in_tool(const tables::PartTables& part, const geometry::ToolBsp& tool, const ToolPose& pose,
                         Visit&& visit) {
  const geometry::Kdop14 volume = geometry::tool_kdop(tool.envelope, pose.tip_mm, pose.axis);
  const bool upright = pose.axis == Eigen::Vector3d::UnitZ();
  std::array<std::uint32_t, tables::kMaxTreeDepth + 1> stack;
  std::size_t size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const std::uint32_t index = stack[--size];
    if (index >= part.node_count()) {
      return Walk::BadTree;
    }
    const tables::BvhNode& node = part.nodes[index];
    if (!overlaps_node(volume, node)) {
      continue;
    }
    if (upright && !geometry::upright_box_may_touch(tool, pose.tip_mm, {node.dop_min[0], node.dop_min[1], node.dop_min[2]},
                                                    {node.dop_max[0], node.dop_max[1], node.dop_max[2]}, 0.0)) {
      continue;
    }
    if (node.point_count > 0) {
      for (std::uint32_t i = node.first_point; i < node.first_point + node.point_count; ++i) {
        const tables::PackedPoint& p = part.points[i];
        const Eigen::Vector3d point(p.x_mm, p.y_mm, p.z_mm);
        if (upright && !geometry::upright_point_may_be_inside(tool, point - pose.tip_mm, 0.0)) {
          continue;
        }
        const geometry::PointClassification result = geometry::classify_at_pose(tool, pose.tip_mm, pose.axis, point);
        if (result.contact == geometry::PointContact::BadTree) {
          return Walk::BadTree;
        }
        if (result.contact != geometry::PointContact::Outside && !visit(i, result)) {
          return Walk::Stopped;
        }
      }
      continue;
    }
    if (size + 2 > stack.size()) {
      return Walk::BadTree;  // deeper than the loader allows: the tables were not loaded by it
    }
    stack[size++] = node.right_child;
    stack[size++] = index + 1;
  }
  return Walk::Finished;
}

Eigen::Vector3d normal_of(const tables::PartTables& part, std::uint32_t point) {
  const tables::PackedPoint& n = part.normals[point];
  return {n.x_mm, n.y_mm, n.z_mm};
}

}  // namespace

ContactResult query_contacts(const tables::PartTables& part, const ToolPose& pose, const ContactParameters& parameters) {
  ContactResult result{QueryStatus::Ok, 0, 0.0, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  if (!pose_is_usable(pose)) {
    result.status = QueryStatus::BadInput;
    return result;
  }
  const double k_world = parameters.stiffness_n_per_device_mm * parameters.device_mm_per_world_mm;
  const Eigen::Vector3d centre = pose.tip_mm + parameters.compliance_centre_mm * pose.axis;
  Eigen::Vector3d force_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_sum = Eigen::Vector3d::Zero();
  const Walk walk = walk_points_in_tool(part, part.tool, pose, [&](std::uint32_t i, const geometry::PointClassification& c) {
    if (c.contact != geometry::PointContact::Penetrating) {
      return true;
    }
    ++result.penetrating_points;
    if (c.depth_mm > result.max_depth_mm) {
      result.max_depth_mm = c.depth_mm;
      result.deepest_point = i;
    }
    // The part pushes the tool out along the point's normal; the tool's own escape direction says
    // the same from the other side. Their average is robust where one of them is poor.
    Eigen::Vector3d direction = normal_of(part, i) - c.escape_direction;
    const double length = direction.norm();
    if (length < 1e-12) {
      return true;  // the two disagree completely: this point gives no direction
    }
    direction /= length;
    const Eigen::Vector3d force = k_world * c.depth_mm * direction;
    const tables::PackedPoint& p = part.points[i];
    force_sum += force;
    torque_sum += (Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm) - centre).cross(force);
    return true;
  });
  if (walk == Walk::BadTree) {
    return {QueryStatus::BadTree, 0, 0.0, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  const double magnitude = force_sum.norm();
  if (magnitude > 0.0) {
    const double scale = k_world * result.max_depth_mm / magnitude;
    result.force_n = scale * force_sum;
    result.torque_nmm = scale * torque_sum;
  }
  return result;
}

Legality check_legal(const tables::PartTables& part, const ToolPose& pose) {
  if (!pose_is_usable(pose)) {
    return Legality::Fault;
  }
  const Walk walk = walk_points_in_tool(part, part.tool, pose, [](std::uint32_t, const geometry::PointClassification& c) {
    return c.contact != geometry::PointContact::Penetrating;
  });
  switch (walk) {
    case Walk::Finished:
      return Legality::Legal;
    case Walk::Stopped:
      return Legality::Illegal;
    case Walk::BadTree:
      break;
  }
  return Legality::Fault;
}

std::uint32_t mark_touched(const tables::PartTables& part, const geometry::ToolBsp& contact_tool, const ToolPose& pose,
                           double contact_tolerance_mm, TriangleSet& touched) {
  if (!pose_is_usable(pose)) {
    return 0;
  }
  const std::size_t before = touched.count();
  const ToolPose inflated{pose.tip_mm - contact_tolerance_mm * pose.axis, pose.axis};
  static_cast<void>(walk_points_in_tool(part, contact_tool, inflated, [&](std::uint32_t i, const geometry::PointClassification& c) {
    static_cast<void>(c);
    touched.insert(part.triangle_ids[i]);
    return true;
  }));
  return static_cast<std::uint32_t>(touched.count() - before);
}

bool build_contact_tool(const geometry::ToolSpec& spec, double contact_tolerance_mm, geometry::ToolBsp& contact_tool) {
  geometry::ToolSpec inflated = spec;
  inflated.diameter_mm += 2.0 * contact_tolerance_mm;
  inflated.flute_length_mm += contact_tolerance_mm;
  inflated.corner_radius_mm += spec.kind == geometry::CutterKind::BullNose ? contact_tolerance_mm : 0.0;
  inflated.holder_diameter_mm += 2.0 * contact_tolerance_mm;
  inflated.holder_length_mm += contact_tolerance_mm;
  return geometry::build_tool_bsp(inflated, contact_tool).ok;
}

}  // namespace stencil::engine
