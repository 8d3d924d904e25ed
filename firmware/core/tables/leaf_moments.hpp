// A leaf's first moments: the centroid of its points and the mean of their normals, for the whole
// leaf and for each group of kLeafGroupPoints lanes (with a radius about the group's centroid). The
// table generator writes them into each LeafBlock and the loader recomputes them to check every
// bit, so both use this one function.
#pragma once

#include "firmware/core/tables/table_format.hpp"

namespace stencil::tables {

struct LeafMoments {
  float centroid_mm[3];
  float mean_normal[3];  // the plain mean: shorter than 1 where the normals differ
  LeafGroupMoments groups[kLeafGroups];
};

// Over the block's first point_count lanes (1 to kMaxLeafPoints; 0 gives zeros), summed in double
// precision in lane order and rounded once to float; a group's over its lanes below point_count
// (zeros for a group with none), its radius the distance of its farthest point from the centroid
// as stored (the float), in double precision, rounded up to a float. Allocation-free.
[[nodiscard]] LeafMoments leaf_moments(const LeafBlock& block);

// Writes the moments into the block's fields (the groups' component by component), as the table
// generator packs a block.
void store_moments(const LeafMoments& moments, LeafBlock& block);

}  // namespace stencil::tables
