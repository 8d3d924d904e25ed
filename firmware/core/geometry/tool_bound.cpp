// The tool's 14-DOP at a pose: each envelope cylinder's exact extent along each slab direction.
#include "firmware/core/geometry/tool_bound.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace stencil::geometry {
namespace {

// Grows the volume by the solid cylinder of the given radius around the axis segment from
// start_mm to end_mm. Along a direction d, a disc of radius rho with unit normal a reaches
// rho * |d - (d.a) a| = rho * sqrt(|d|^2 - (d.a)^2) beyond its centre; the cylinder is the convex
// hull of its two end discs.
// sqrt(|d|^2 - (d.a)^2) per slab direction d for the upright axis a = +z: 1, 1, 0, then sqrt(2)
// four times. 1.4142135623730951 is sqrt(2.0) correctly rounded, which std::sqrt returns too, so
// the upright tool (every query of the 3-axis mill) gets the same bound without the square roots.
constexpr std::array<double, kKdopSlabCount> kUprightReach = {1.0, 1.0, 0.0, 1.4142135623730951, 1.4142135623730951,
                                                              1.4142135623730951, 1.4142135623730951};

void add_cylinder(Kdop14& volume, const Eigen::Vector3d& start_mm, const Eigen::Vector3d& end_mm,
                  const Eigen::Vector3d& unit_axis, double radius_mm) {
  const auto start = kdop_projections(start_mm);
  const auto end = kdop_projections(end_mm);
  const auto axis = kdop_projections(unit_axis);
  std::array<double, kKdopSlabCount> reach;  // per unit of radius
  if (unit_axis == Eigen::Vector3d::UnitZ()) {
    reach = kUprightReach;
  } else {
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      const double length_squared = slab < 3 ? 1.0 : 3.0;
      reach[slab] = std::sqrt(std::max(0.0, length_squared - axis[slab] * axis[slab]));
    }
  }
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    volume.min[slab] = std::min(volume.min[slab], std::min(start[slab], end[slab]) - radius_mm * reach[slab]);
    volume.max[slab] = std::max(volume.max[slab], std::max(start[slab], end[slab]) + radius_mm * reach[slab]);
  }
}

}  // namespace

Kdop14 tool_kdop(const ToolEnvelope& envelope, const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& unit_axis) {
  Kdop14 volume = Kdop14::empty();
  const Eigen::Vector3d flute_top = tip_mm + envelope.flute_length_mm * unit_axis;
  const Eigen::Vector3d holder_top = tip_mm + envelope.total_length_mm * unit_axis;
  add_cylinder(volume, tip_mm, flute_top, unit_axis, envelope.cutter_radius_mm);
  add_cylinder(volume, flute_top, holder_top, unit_axis, envelope.holder_radius_mm);
  // Grown by twice the surface tolerance: everything the BSP may call touching is inside, and so is
  // the rounding of the projections above.
  return volume.enlarged(kToolBoundMargin_mm);
}

}  // namespace stencil::geometry
