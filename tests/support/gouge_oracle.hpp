// The oracle of the engine tests: how deep a ball end mill cuts into the part's true triangles.
#pragma once

#include <algorithm>

#include <Eigen/Core>

#include "firmware/core/tables/part_tables.hpp"
#include "sim/mill/triangle_distance.hpp"

namespace stencil::test {

// Depth of the cut (0 when none) of the ball end mill with its tip at `tip`: the cutter is a capsule
// of radius R around the axis from tip + R to the top of the flutes; every triangle is measured
// exactly, none skipped.
inline double ball_end_gouge_mm(const tables::PartTables& part, const Eigen::Vector3d& tip) {
  const double radius = part.tool.envelope.cutter_radius_mm;
  const Eigen::Vector3d low = tip + Eigen::Vector3d(0, 0, radius);
  const Eigen::Vector3d high = tip + Eigen::Vector3d(0, 0, part.tool.envelope.flute_length_mm);
  double deepest = 0.0;
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    const auto& v = part.triangles[t].vertices;
    const auto vertex = [&](int i) { return Eigen::Vector3d(v[i].x_mm, v[i].y_mm, v[i].z_mm); };
    deepest = std::max(deepest, radius - sim::segment_triangle_distance(low, high, vertex(0), vertex(1), vertex(2)));
  }
  return deepest;
}

}  // namespace stencil::test
