// A leaf's first moments: the centroid of its points and the mean of their normals. The table
// generator writes them into each LeafBlock and the loader recomputes them to check every bit, so
// both use this one function.
#pragma once

#include "firmware/core/tables/table_format.hpp"

namespace stencil::tables {

struct LeafMoments {
  float centroid_mm[3];
  float mean_normal[3];  // the plain mean: shorter than 1 where the normals differ
};

// Over the block's first point_count lanes (1 to kMaxLeafPoints; 0 gives zeros), summed in double
// precision in lane order and rounded once to float. Allocation-free.
[[nodiscard]] LeafMoments leaf_moments(const LeafBlock& block);

}  // namespace stencil::tables
