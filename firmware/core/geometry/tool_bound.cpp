// The tool's 14-DOP at a pose: each envelope cylinder's exact extent along each slab direction.
#include "firmware/core/geometry/tool_bound.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace stencil::geometry {
namespace {

// The tool is the union of two solid cylinders about its axis (the cutter's, from the tip to the
// flute's top, and the holder's above it). Along a direction d, a disc of radius rho with unit
// normal a reaches rho * |d - (d.a) a| = rho * sqrt(|d|^2 - (d.a)^2) beyond its centre, and a
// cylinder is the convex hull of its two end discs.
// sqrt(|d|^2 - (d.a)^2) per slab direction d for the upright axis a = +z: 1, 1, 0, then sqrt(2)
// four times. 1.4142135623730951 is sqrt(2.0) correctly rounded, which std::sqrt returns too, so
// the upright tool (every query of the 3-axis mill) gets the same bound without the square roots.
constexpr std::array<double, kKdopSlabCount> kUprightReach = {1.0, 1.0, 0.0, 1.4142135623730951, 1.4142135623730951,
                                                              1.4142135623730951, 1.4142135623730951};

// The reach per unit of radius along each slab direction, for a disc about unit_axis.
std::array<double, kKdopSlabCount> disc_reach(const Eigen::Vector3d& unit_axis) {
  if (unit_axis == Eigen::Vector3d::UnitZ()) {
    return kUprightReach;
  }
  const auto axis = kdop_projections(unit_axis);
  std::array<double, kKdopSlabCount> reach;
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    const double length_squared = slab < 3 ? 1.0 : 3.0;
    reach[slab] = std::sqrt(std::max(0.0, length_squared - axis[slab] * axis[slab]));
  }
  return reach;
}

}  // namespace

// Both cylinders and the margin in one pass, each bound written once. Not built up in a volume (an
// empty one grown by each cylinder, then enlarged): each step would reload what the one before had
// just stored, in pieces of another width, which the CPU cannot forward from its store buffer, and
// those stalls took a query in free space longer than its work.
Kdop14 tool_kdop(const ToolEnvelope& envelope, const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& unit_axis) {
  const auto tip = kdop_projections(tip_mm);
  const auto flute_top = kdop_projections(tip_mm + envelope.flute_length_mm * unit_axis);
  const auto holder_top = kdop_projections(tip_mm + envelope.total_length_mm * unit_axis);
  const auto reach = disc_reach(unit_axis);
  Kdop14 volume;
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    const double cutter = envelope.cutter_radius_mm * reach[slab];
    const double holder = envelope.holder_radius_mm * reach[slab];
    // Grown by twice the surface tolerance: everything the BSP may call touching is inside, and so
    // is the rounding of the projections above.
    const double margin = kToolBoundMargin_mm * kKdopSlabLength[slab];
    volume.min[slab] = std::min(std::min(tip[slab], flute_top[slab]) - cutter,
                                std::min(flute_top[slab], holder_top[slab]) - holder) - margin;
    volume.max[slab] = std::max(std::max(tip[slab], flute_top[slab]) + cutter,
                                std::max(flute_top[slab], holder_top[slab]) + holder) + margin;
  }
  return volume;
}

}  // namespace stencil::geometry
