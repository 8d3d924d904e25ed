// Upright-tool culling: the profile's radius at a height, a box against the ball or the column.
#include "firmware/core/geometry/upright_tool.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::geometry {

double upright_radius_up_to(const ToolSpec& tool, double height_mm) {
  const double radius = tool.diameter_mm / 2.0;
  const double z = height_mm;
  if (z > tool.flute_length_mm) {
    return tool.holder_diameter_mm / 2.0;
  }
  switch (tool.kind) {
    case CutterKind::Flat:
      return radius;
    case CutterKind::Ball:
      return z >= radius ? radius : std::sqrt(std::max(0.0, radius * radius - (radius - z) * (radius - z)));
    case CutterKind::BullNose: {
      const double corner = tool.corner_radius_mm;
      return z >= corner ? radius
                         : (radius - corner) + std::sqrt(std::max(0.0, corner * corner - (corner - z) * (corner - z)));
    }
  }
  return radius;
}

bool upright_box_may_touch(const ToolBsp& tool, const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& low,
                           const Eigen::Vector3d& high, double margin_mm) {
  const ToolSpec& spec = tool.spec;
  const double z_low = low.z() - tip_mm.z();
  const double z_high = high.z() - tip_mm.z();
  if (z_high < margin_mm || z_low > tool.envelope.total_length_mm) {
    return false;  // entirely below the tip or above the holder
  }
  const double dx = std::max({low.x() - tip_mm.x(), tip_mm.x() - high.x(), 0.0});
  const double dy = std::max({low.y() - tip_mm.y(), tip_mm.y() - high.y(), 0.0});
  const double horizontal_squared = dx * dx + dy * dy;
  const double reach = upright_radius_up_to(spec, std::min(z_high, tool.envelope.total_length_mm));
  if (horizontal_squared >= reach * reach) {
    return false;
  }
  // A box wholly below a ball's centre can only meet the ball: test the sphere itself.
  const double radius = spec.diameter_mm / 2.0;
  if (spec.kind == CutterKind::Ball && z_high < radius) {
    const double dz = radius - z_high;  // the box's top is its nearest height to the centre
    return horizontal_squared + dz * dz < (radius - margin_mm) * (radius - margin_mm) || margin_mm >= radius;
  }
  return true;
}

bool upright_point_may_be_inside(const ToolBsp& tool, const Eigen::Vector3d& local_mm, double margin_mm) {
  const ToolSpec& spec = tool.spec;
  const ToolEnvelope& envelope = tool.envelope;
  const double z = local_mm.z();
  if (z < margin_mm || z > envelope.total_length_mm) {
    return false;
  }
  const double r_squared = local_mm.x() * local_mm.x() + local_mm.y() * local_mm.y();
  if (z > envelope.flute_length_mm) {
    return r_squared < envelope.holder_radius_mm * envelope.holder_radius_mm;
  }
  const double radius = envelope.cutter_radius_mm;
  if (r_squared >= radius * radius) {
    return false;
  }
  if (spec.kind == CutterKind::Ball && z < radius) {
    return r_squared + (z - radius) * (z - radius) < radius * radius;
  }
  if (spec.kind == CutterKind::BullNose && z < spec.corner_radius_mm) {
    const double flat = radius - spec.corner_radius_mm;
    if (r_squared <= flat * flat) {
      return true;
    }
    const double r = std::sqrt(r_squared);
    const double corner = spec.corner_radius_mm;
    return (r - flat) * (r - flat) + (z - corner) * (z - corner) < corner * corner;
  }
  return true;
}

}  // namespace stencil::geometry
