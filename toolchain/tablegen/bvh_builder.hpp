// Builds the binary 14-DOP tree over the points, in the table's depth-first layout.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/core/tables/table_format.hpp"

namespace stencil::tablegen {

struct PointTree {
  std::vector<std::uint32_t> order;     // order[i]: which input point goes to table slot i
  std::vector<tables::BvhNode> nodes;   // root first, depth-first
};

// Splits along the slab of largest extent (ties broken by input index, so the result is
// deterministic) until a node has at most kMaxLeafPoints points, at the whole leaf nearest the
// median (point_tree_left_count): every leaf but the last holds kMaxLeafPoints points, so the
// query's 64-lane kernels run full and a tree has as few nodes as it can. The two halves of the
// root are built on two threads when threads > 1; the result does not depend on `threads`.
// Within a leaf, the points are ordered so that each group of kLeafGroupPoints lanes lies close
// together (halved along the widest slab at a whole number of groups, down to one group).
// The DOPs are computed from `points` exactly as given (the float values the table will hold).
[[nodiscard]] PointTree build_point_tree(const std::vector<tables::PackedPoint>& points, unsigned threads);

// How many of `count` (> kMaxLeafPoints) points a node's left child takes: half its leaves' worth.
[[nodiscard]] std::uint64_t point_tree_left_count(std::uint64_t count);

// Nodes a tree over `count` points has (for capacity checks).
[[nodiscard]] std::uint64_t point_tree_node_count(std::uint64_t count);

}  // namespace stencil::tablegen
