// Lane-wise depth, escape direction and force for the points of one leaf (upright tool).
#include "firmware/stencil/leaf_contacts.hpp"

#include <cmath>


namespace stencil::engine {
namespace {

using geometry::SurfaceKind;

// As in classify_at_pose: below this radius a point's radial direction is meaningless, and below
// this distance from a sphere's or torus's centre its gradient is.
constexpr double kOnAxisRadius_mm = 1e-12;
constexpr double kDegenerateDistance_mm = 1e-12;
constexpr double kInvSqrt2 = 0.70710678118654752;


// Eigen 3.4 runs select() and boolean reductions a lane at a time, so the kernels below use only
// arithmetic, min/max and sums over the lanes (which it vectorises), and patch the rare lanes a
// select would have treated apart (a point on the axis or at a centre) in a plain loop afterwards.

struct Meridian {
  LeafLanes x, y, z;  // relative to the tip
  LeafLanes r;        // set only where a kernel needs it (a square root per point)
};

void offsets_from(const LeafContacts& leaf, const Eigen::Vector3d& tip, Meridian& m) {
  m.x = leaf.x - tip.x();
  m.y = leaf.y - tip.y();
  m.z = leaf.z - tip.z();
}

void radii_of(Meridian& m) { m.r = (m.x * m.x + m.y * m.y).sqrt(); }

// The meridian escape direction (radial, axial) turned into the world: radial along (x, y) / r,
// or along +y on the axis (classify_at_pose's fixed perpendicular to +z).
void escape_to_world(const Meridian& m, const LeafLanes& radial, const LeafLanes& axial, LeafContacts& leaf) {
  const LeafLanes inverse = m.r.max(kOnAxisRadius_mm).inverse();  // one division, not two
  leaf.ex = radial * (m.x * inverse);
  leaf.ey = radial * (m.y * inverse);
  leaf.ez = axial;
  if (!(m.r.minCoeff() > kOnAxisRadius_mm)) {
    for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
      if (!(m.r[lane] > kOnAxisRadius_mm)) {
        leaf.ex[lane] = 0.0;
        leaf.ey[lane] = radial[lane];
      }
    }
  }
}

// Depth 0 where it is not beyond the tolerance (classify_meridian's Touching), and in the lanes
// past the leaf's count, so sums and maxima may run over every lane.
void settle_depths(const LeafLanes& interior, LeafContacts& leaf) {
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    leaf.depth[lane] = interior[lane] > geometry::kSurfaceTolerance_mm ? interior[lane] : 0.0;
  }
  for (std::uint32_t lane = leaf.count; lane < tables::kMaxLeafPoints; ++lane) {
    leaf.depth[lane] = 0.0;
    leaf.in_tool[lane] = false;
  }
}

}  // namespace

void load_leaf(const tables::PartTables& part, std::uint32_t first, std::uint32_t count, LeafContacts& leaf) {
  leaf.first = first;
  leaf.count = count;
  const tables::PackedPoint* points = &part.points[first];
  const tables::PackedPoint* normals = &part.normals[first];
  for (std::uint32_t lane = 0; lane < count; ++lane) {
    leaf.x[lane] = double{points[lane].x_mm};
    leaf.y[lane] = double{points[lane].y_mm};
    leaf.z[lane] = double{points[lane].z_mm};
    leaf.nx[lane] = double{normals[lane].x_mm};
    leaf.ny[lane] = double{normals[lane].y_mm};
    leaf.nz[lane] = double{normals[lane].z_mm};
  }
  for (std::uint32_t lane = count; lane < tables::kMaxLeafPoints; ++lane) {
    leaf.x[lane] = leaf.x[count - 1];
    leaf.y[lane] = leaf.y[count - 1];
    leaf.z[lane] = leaf.z[count - 1];
    leaf.nx[lane] = leaf.nx[count - 1];
    leaf.ny[lane] = leaf.ny[count - 1];
    leaf.nz[lane] = leaf.nz[count - 1];
  }
}

bool region_leaf_contacts(const geometry::ToolBsp& tool, std::uint8_t region, bool or_outside,
                          const Eigen::Vector3d& tip_mm, LeafContacts& leaf) {
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
  const double sign = surface.solid_side == geometry::SolidSide::Below ? 1.0 : -1.0;
  // Each kind with no more square roots and divisions than it needs: they bound the time here.
  Meridian m;
  offsets_from(leaf, tip_mm, m);
  LeafLanes f;
  switch (surface.kind) {
    case SurfaceKind::PlaneZ:
      f = m.z - surface.center_z_mm;
      leaf.ex.setZero();
      leaf.ey.setZero();
      leaf.ez.setConstant(sign);
      break;
    case SurfaceKind::Cylinder: {
      radii_of(m);
      f = m.r - surface.radius_mm;
      const LeafLanes radial = LeafLanes::Constant(sign);
      escape_to_world(m, radial, LeafLanes::Zero(), leaf);
      break;
    }
    case SurfaceKind::Sphere: {
      // Centred on the axis: the meridian gradient (r, dz) / length is the 3-D one (x, y, dz) / length.
      const LeafLanes dz = m.z - surface.center_z_mm;
      const LeafLanes length = (m.x * m.x + m.y * m.y + dz * dz).sqrt();
      f = length - surface.radius_mm;
      const LeafLanes inverse = sign * length.max(kDegenerateDistance_mm).inverse();
      leaf.ex = m.x * inverse;
      leaf.ey = m.y * inverse;
      leaf.ez = dz * inverse;
      if (!(length.minCoeff() >= kDegenerateDistance_mm)) {
        for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
          if (!(length[lane] >= kDegenerateDistance_mm)) {
            // At the centre: classify_at_pose's (1, -1) / sqrt(2) in the meridian, radial along +y.
            leaf.ex[lane] = 0.0;
            leaf.ey[lane] = kInvSqrt2;
            leaf.ez[lane] = -kInvSqrt2;
          }
        }
      }
      break;
    }
    case SurfaceKind::Torus: {
      radii_of(m);
      const LeafLanes dr = m.r - surface.center_r_mm;
      const LeafLanes dz = m.z - surface.center_z_mm;
      const LeafLanes length = (dr * dr + dz * dz).sqrt();
      f = length - surface.radius_mm;
      const LeafLanes inverse = sign * length.max(kDegenerateDistance_mm).inverse();
      LeafLanes radial = dr * inverse;
      LeafLanes axial = dz * inverse;
      if (!(length.minCoeff() >= kDegenerateDistance_mm)) {
        for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
          if (!(length[lane] >= kDegenerateDistance_mm)) {
            radial[lane] = kInvSqrt2;
            axial[lane] = -kInvSqrt2;
          }
        }
      }
      escape_to_world(m, radial, axial, leaf);
      break;
    }
    default:
      return false;
  }
  const LeafLanes depth = -sign * f;  // the interior distance to the region's surface
  // Straddling the region's boundary, a point is in the tool exactly when the boundary test that
  // leads to the region passes: -tolerance <= that same interior distance.
  if (or_outside) {
    for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
      leaf.in_tool[lane] = -geometry::kSurfaceTolerance_mm <= depth[lane];
    }
  } else {
    leaf.in_tool.fill(true);
  }
  settle_depths(depth, leaf);
  // An infinity or NaN anywhere makes the sum non-finite (inf - inf is NaN).
  return std::isfinite((f + leaf.ex + leaf.ey + leaf.ez).sum());
}

namespace {

bool part_contacts(const geometry::ToolBsp& tool, const geometry::BoxPart& part, const Eigen::Vector3d& tip_mm,
                   LeafContacts& leaf) {
  if (part.cover == geometry::BoxCover::Outside) {
    leaf.depth.setZero();
    leaf.ex.setZero();
    leaf.ey.setZero();
    leaf.ez.setZero();
    leaf.in_tool.fill(false);
    return true;
  }
  return region_leaf_contacts(tool, part.region, part.cover == geometry::BoxCover::RegionOrOutside, tip_mm, leaf);
}

}  // namespace

bool split_leaf_contacts(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover,
                         const Eigen::Vector3d& tip_mm, LeafContacts& leaf) {
  if (!part_contacts(tool, cover.below, tip_mm, leaf)) {
    return false;
  }
  const LeafLanes depth = leaf.depth, ex = leaf.ex, ey = leaf.ey, ez = leaf.ez;
  const std::array<bool, tables::kMaxLeafPoints> in_tool = leaf.in_tool;
  if (!part_contacts(tool, cover.above, tip_mm, leaf)) {
    return false;
  }
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    // classify_meridian's partition test, on the same z: below when z - split < 0.
    if ((leaf.z[lane] - tip_mm.z()) - cover.split_z_mm < 0.0) {
      leaf.depth[lane] = depth[lane];
      leaf.ex[lane] = ex[lane];
      leaf.ey[lane] = ey[lane];
      leaf.ez[lane] = ez[lane];
      leaf.in_tool[lane] = in_tool[lane];
    }
  }
  return true;
}

bool mixed_leaf_contacts(const geometry::ToolBsp& tool, const Eigen::Vector3d& tip_mm, LeafContacts& leaf) {
  Meridian m;
  offsets_from(leaf, tip_mm, m);
  radii_of(m);
  LeafLanes radial, axial, interior;
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    // No outline pre-filter here: it would drop points touching the surface from just outside,
    // which the settled leaves keep; the tool tree decides them all alike.
    const geometry::MeridianClassification c = geometry::classify_meridian(tool, {m.r[lane], m.z[lane]});
    if (c.contact == geometry::PointContact::BadTree) {
      return false;
    }
    const bool inside = c.contact != geometry::PointContact::Outside;
    leaf.in_tool[lane] = inside;
    interior[lane] = inside ? c.depth_mm : 0.0;
    radial[lane] = inside ? c.escape.radial : 0.0;
    axial[lane] = inside ? c.escape.axial : 0.0;
  }
  escape_to_world(m, radial, axial, leaf);
  settle_depths(interior, leaf);
  return true;
}

void leaf_forces(const LeafContacts& leaf, double k_world, const Eigen::Vector3d& centre, LeafForces& forces) {
  const LeafLanes vx = leaf.nx - leaf.ex;
  const LeafLanes vy = leaf.ny - leaf.ey;
  const LeafLanes vz = leaf.nz - leaf.ez;
  const LeafLanes length = (vx * vx + vy * vy + vz * vz).sqrt();
  LeafLanes scale = k_world * leaf.depth / length.max(kNoDirection);
  if (!(length.minCoeff() >= kNoDirection)) {
    for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
      if (!(length[lane] >= kNoDirection)) {
        scale[lane] = 0.0;  // the normal and the escape direction cancel: no direction
      }
    }
  }
  forces.fx = scale * vx;
  forces.fy = scale * vy;
  forces.fz = scale * vz;
  const LeafLanes rx = leaf.x - centre.x();
  const LeafLanes ry = leaf.y - centre.y();
  const LeafLanes rz = leaf.z - centre.z();
  forces.tx = ry * forces.fz - rz * forces.fy;
  forces.ty = rz * forces.fx - rx * forces.fz;
  forces.tz = rx * forces.fy - ry * forces.fx;
}

}  // namespace stencil::engine
