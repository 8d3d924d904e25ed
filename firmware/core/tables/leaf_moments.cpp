#include "firmware/core/tables/leaf_moments.hpp"

#include <algorithm>

namespace stencil::tables {

LeafMoments leaf_moments(const LeafBlock& block) {
  LeafMoments moments{};
  const std::uint32_t count = std::min(block.point_count, kMaxLeafPoints);
  if (count == 0) {
    return moments;
  }
  double sums[6] = {};
  for (std::uint32_t lane = 0; lane < count; ++lane) {
    sums[0] += double{block.x_mm[lane]};
    sums[1] += double{block.y_mm[lane]};
    sums[2] += double{block.z_mm[lane]};
    sums[3] += double{block.nx[lane]};
    sums[4] += double{block.ny[lane]};
    sums[5] += double{block.nz[lane]};
  }
  for (int axis = 0; axis < 3; ++axis) {
    moments.centroid_mm[axis] = static_cast<float>(sums[axis] / static_cast<double>(count));
    moments.mean_normal[axis] = static_cast<float>(sums[3 + axis] / static_cast<double>(count));
  }
  return moments;
}

}  // namespace stencil::tables
