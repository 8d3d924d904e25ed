// The 14-DOP bounding volume: building, merging, enlarging and the slab overlap test.
#include "firmware/core/geometry/kdop14.hpp"

#include <algorithm>
#include <limits>

namespace stencil::geometry {

Kdop14 Kdop14::empty() {
  Kdop14 volume{};
  volume.min.fill(std::numeric_limits<double>::infinity());
  volume.max.fill(-std::numeric_limits<double>::infinity());
  return volume;
}

bool Kdop14::is_empty() const {
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    if (!(min[slab] <= max[slab])) {
      return true;
    }
  }
  return false;
}

void Kdop14::merge(const Kdop14& other) {
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    min[slab] = std::min(min[slab], other.min[slab]);
    max[slab] = std::max(max[slab], other.max[slab]);
  }
}

Kdop14 Kdop14::enlarged(double margin_mm) const {
  Kdop14 volume;
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    volume.min[slab] = min[slab] - margin_mm * kKdopSlabLength[slab];
    volume.max[slab] = max[slab] + margin_mm * kKdopSlabLength[slab];
  }
  return volume;
}

bool Kdop14::contains(const Eigen::Vector3d& point_mm, double tolerance_mm) const {
  const auto projection = kdop_projections(point_mm);
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    const double widen = tolerance_mm * kKdopSlabLength[slab];
    if (projection[slab] < min[slab] - widen || projection[slab] > max[slab] + widen) {
      return false;
    }
  }
  return true;
}

Kdop14 kdop_of_points(std::span<const Eigen::Vector3d> points_mm) {
  Kdop14 volume = Kdop14::empty();
  for (const Eigen::Vector3d& point : points_mm) {
    volume.add(point);
  }
  return volume;
}

Kdop14 merged(const Kdop14& a, const Kdop14& b) {
  Kdop14 volume = a;
  volume.merge(b);
  return volume;
}

bool overlaps(const Kdop14& a, const Kdop14& b) {
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    // Written so that a NaN bound reads as "overlapping": a damaged volume is looked into, never skipped.
    if (a.min[slab] > b.max[slab] || b.min[slab] > a.max[slab]) {
      return false;
    }
  }
  return true;
}

}  // namespace stencil::geometry
