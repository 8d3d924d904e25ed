#include "firmware/core/tables/leaf_moments.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace stencil::tables {
namespace {

// The centroid and mean normal of lanes [first, first + count) (count > 0) into centroid and
// mean_normal.
void means(const LeafBlock& block, std::uint32_t first, std::uint32_t count, float (&centroid)[3], float (&mean_normal)[3]) {
  double sums[6] = {};
  for (std::uint32_t lane = first; lane < first + count; ++lane) {
    sums[0] += double{block.x_mm[lane]};
    sums[1] += double{block.y_mm[lane]};
    sums[2] += double{block.z_mm[lane]};
    sums[3] += double{block.nx[lane]};
    sums[4] += double{block.ny[lane]};
    sums[5] += double{block.nz[lane]};
  }
  for (int axis = 0; axis < 3; ++axis) {
    centroid[axis] = static_cast<float>(sums[axis] / static_cast<double>(count));
    mean_normal[axis] = static_cast<float>(sums[3 + axis] / static_cast<double>(count));
  }
}

LeafGroupMoments group_moments(const LeafBlock& block, std::uint32_t first, std::uint32_t count) {
  LeafGroupMoments group{};
  means(block, first, count, group.centroid_mm, group.mean_normal);
  // The centroid read back as the float it is: GCC 12 at -O3 has been seen to fold double(float(x))
  // to x (see the table writer's sphere), which would measure from a point the engine never sees.
  volatile float stored[3] = {group.centroid_mm[0], group.centroid_mm[1], group.centroid_mm[2]};
  const double cx = stored[0], cy = stored[1], cz = stored[2];
  double radius = 0.0;
  for (std::uint32_t lane = first; lane < first + count; ++lane) {
    const double dx = double{block.x_mm[lane]} - cx;
    const double dy = double{block.y_mm[lane]} - cy;
    const double dz = double{block.z_mm[lane]} - cz;
    radius = std::max(radius, std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  // The float at or above the double: a radius that holds every point as the engine measures it.
  const auto rounded = static_cast<float>(radius);
  group.radius_mm = double{rounded} >= radius ? rounded : std::nextafter(rounded, std::numeric_limits<float>::infinity());
  return group;
}

}  // namespace

LeafMoments leaf_moments(const LeafBlock& block) {
  LeafMoments moments{};
  const std::uint32_t count = std::min(block.point_count, kMaxLeafPoints);
  if (count == 0) {
    return moments;
  }
  means(block, 0, count, moments.centroid_mm, moments.mean_normal);
  for (std::uint32_t group = 0; group < kLeafGroups; ++group) {
    const std::uint32_t first = group * kLeafGroupPoints;
    if (first < count) {
      moments.groups[group] = group_moments(block, first, std::min(kLeafGroupPoints, count - first));
    }
  }
  return moments;
}

void store_moments(const LeafMoments& moments, LeafBlock& block) {
  std::copy(std::begin(moments.centroid_mm), std::end(moments.centroid_mm), std::begin(block.centroid_mm));
  std::copy(std::begin(moments.mean_normal), std::end(moments.mean_normal), std::begin(block.mean_normal));
  for (std::uint32_t group = 0; group < kLeafGroups; ++group) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      block.group_centroid_mm[axis][group] = moments.groups[group].centroid_mm[axis];
      block.group_mean_normal[axis][group] = moments.groups[group].mean_normal[axis];
    }
    block.group_radius_mm[group] = moments.groups[group].radius_mm;
  }
}

}  // namespace stencil::tables
