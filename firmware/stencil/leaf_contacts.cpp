// Lane-wise depth, escape direction and force for the points of one leaf (upright tool).
#include "firmware/stencil/leaf_contacts.hpp"

#include <cmath>

#include "firmware/geometry/upright_tool.hpp"

namespace stencil::engine {
namespace {

using geometry::SurfaceKind;

// As in classify_at_pose: below this radius a point's radial direction is meaningless, and below
// this distance from a sphere's or torus's centre its gradient is.
constexpr double kOnAxisRadius_mm = 1e-12;
constexpr double kDegenerateDistance_mm = 1e-12;
constexpr double kInvSqrt2 = 0.70710678118654752;

// Below this length a point's normal and the tool's escape direction cancel: no direction.
constexpr double kNoDirection = 1e-12;

struct Meridian {
  LeafLanes x, y, z;  // relative to the tip
  LeafLanes r;
};

void meridian_of(const LeafContacts& leaf, const Eigen::Vector3d& tip, Meridian& m) {
  m.x = leaf.x - tip.x();
  m.y = leaf.y - tip.y();
  m.z = leaf.z - tip.z();
  m.r = (m.x * m.x + m.y * m.y).sqrt();
}

// The meridian escape direction (radial, axial) turned into the world: radial along (x, y) / r,
// or along +y on the axis (classify_at_pose's fixed perpendicular to +z).
void escape_to_world(const Meridian& m, const LeafLanes& radial, const LeafLanes& axial, LeafContacts& leaf) {
  const auto off_axis = m.r > kOnAxisRadius_mm;
  const LeafLanes divisor = off_axis.select(m.r, 1.0);
  leaf.ex = radial * off_axis.select(m.x / divisor, 0.0);
  leaf.ey = radial * off_axis.select(m.y / divisor, 1.0);
  leaf.ez = axial;
}

bool all_finite(const LeafLanes& a, const LeafLanes& b, const LeafLanes& c) {
  return a.isFinite().all() && b.isFinite().all() && c.isFinite().all();
}

}  // namespace

void load_leaf(const tables::PartTables& part, std::uint32_t first, std::uint32_t count, LeafContacts& leaf) {
  leaf.first = first;
  leaf.count = count;
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    const std::uint32_t i = first + (lane < count ? lane : count - 1);
    const tables::PackedPoint& p = part.points[i];
    const tables::PackedPoint& n = part.normals[i];
    leaf.x[lane] = double{p.x_mm};
    leaf.y[lane] = double{p.y_mm};
    leaf.z[lane] = double{p.z_mm};
    leaf.nx[lane] = double{n.x_mm};
    leaf.ny[lane] = double{n.y_mm};
    leaf.nz[lane] = double{n.z_mm};
  }
}

bool region_leaf_contacts(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside,
                          const Eigen::Vector3d& tip_mm, LeafContacts& leaf) {
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
  const double sign = surface.solid_side == geometry::SolidSide::Below ? 1.0 : -1.0;
  Meridian m;
  meridian_of(leaf, tip_mm, m);
  LeafLanes f, radial, axial;
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      f = m.z - surface.center_z_mm;
      radial.setZero();
      axial.setConstant(sign);
      break;
    case SurfaceKind::Cylinder:
      f = m.r - surface.radius_mm;
      radial.setConstant(sign);
      axial.setZero();
      break;
    case SurfaceKind::Sphere:
    case SurfaceKind::Torus: {
      const double centre_r = surface.kind == SurfaceKind::Torus ? surface.center_r_mm : 0.0;
      const LeafLanes dr = m.r - centre_r;
      const LeafLanes dz = m.z - surface.center_z_mm;
      const LeafLanes length = (dr * dr + dz * dz).sqrt();
      f = length - surface.radius_mm;
      const auto regular = length >= kDegenerateDistance_mm;
      const LeafLanes divisor = regular.select(length, 1.0);
      radial = regular.select(sign * dr / divisor, kInvSqrt2);
      axial = regular.select(sign * dz / divisor, -kInvSqrt2);
      break;
    }
    default:
      return false;
  }
  const LeafLanes depth = -sign * f;  // the interior distance, as classify_meridian computes it
  escape_to_world(m, radial, axial, leaf);
  // Straddling the region's boundary, a point is in the tool exactly when the boundary test that
  // leads to the region passes: -tolerance <= that same interior distance.
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    leaf.in_tool[lane] = !or_outside || -geometry::kSurfaceTolerance_mm <= depth[lane];
  }
  // classify_meridian calls a point in a region Touching at depth <= tolerance, with depth 0.
  leaf.depth = (depth > geometry::kSurfaceTolerance_mm).select(depth, 0.0);
  return all_finite(f, radial, axial);
}

bool mixed_leaf_contacts(const geometry::ToolBsp& tool, const Eigen::Vector3d& tip_mm, LeafContacts& leaf) {
  Meridian m;
  meridian_of(leaf, tip_mm, m);
  LeafLanes radial, axial;
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    const Eigen::Vector3d local(m.x[lane], m.y[lane], m.z[lane]);
    geometry::MeridianClassification c{geometry::PointContact::Outside, 0, 0.0, {0.0, 0.0}};
    if (geometry::upright_point_may_be_inside(tool, local, 0.0)) {
      c = geometry::classify_meridian(tool, {m.r[lane], m.z[lane]});
    }
    if (c.contact == geometry::PointContact::BadTree) {
      return false;
    }
    const bool inside = c.contact != geometry::PointContact::Outside;
    leaf.in_tool[lane] = inside;
    leaf.depth[lane] = inside ? c.depth_mm : 0.0;
    radial[lane] = inside ? c.escape.radial : 0.0;
    axial[lane] = inside ? c.escape.axial : 0.0;
  }
  escape_to_world(m, radial, axial, leaf);
  return true;
}

void leaf_forces(const LeafContacts& leaf, double k_world, const Eigen::Vector3d& centre, LeafForces& forces) {
  const LeafLanes vx = leaf.nx - leaf.ex;
  const LeafLanes vy = leaf.ny - leaf.ey;
  const LeafLanes vz = leaf.nz - leaf.ez;
  const LeafLanes length = (vx * vx + vy * vy + vz * vz).sqrt();
  const auto has_direction = length >= kNoDirection;
  const LeafLanes divisor = has_direction.select(length, 1.0);
  const LeafLanes scale = has_direction.select(k_world * leaf.depth, 0.0);
  forces.fx = scale * (vx / divisor);
  forces.fy = scale * (vy / divisor);
  forces.fz = scale * (vz / divisor);
  const LeafLanes rx = leaf.x - centre.x();
  const LeafLanes ry = leaf.y - centre.y();
  const LeafLanes rz = leaf.z - centre.z();
  forces.tx = ry * forces.fz - rz * forces.fy;
  forces.ty = rz * forces.fx - rx * forces.fz;
  forces.tz = rx * forces.fy - ry * forces.fx;
}

}  // namespace stencil::engine
