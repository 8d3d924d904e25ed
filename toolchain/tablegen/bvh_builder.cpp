// 14-DOP tree split at whole leaves near the median; node positions are known in advance, so
// subtrees build independently.
#include "toolchain/tablegen/bvh_builder.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <numeric>
#include <thread>
#include <utility>
#include <vector>

#include "firmware/core/geometry/kdop14.hpp"

namespace stencil::tablegen {
namespace {

using geometry::kKdopSlabCount;

Eigen::Vector3d to_vector(const tables::PackedPoint& point) { return {point.x_mm, point.y_mm, point.z_mm}; }

// Each point's key (its projection on the split's slab) beside its index, for one thread's splits:
// sized once, before the threads start (the tests' leak-checking allocator is not thread-safe).
using SplitKeys = std::vector<std::pair<double, std::uint32_t>>;

class TreeBuilder {
 public:
  TreeBuilder(const std::vector<tables::PackedPoint>& points, PointTree& tree) : points_(points), tree_(tree) {}

  // Builds the subtree over order[begin, end) into nodes starting at node_index.
  void build(std::uint32_t node_index, std::uint32_t begin, std::uint32_t end, SplitKeys& keys) {
    const geometry::Kdop14 volume = volume_of(begin, end);
    tables::BvhNode& node = tree_.nodes[node_index];
    std::memset(&node, 0, sizeof(node));
    std::copy(volume.min.begin(), volume.min.end(), node.dop_min);
    std::copy(volume.max.begin(), volume.max.end(), node.dop_max);
    const std::uint32_t count = end - begin;
    if (count <= tables::kMaxLeafPoints) {
      node.first_point = begin;
      node.point_count = count;
      order_groups(volume, begin, end, keys);
      return;
    }
    const std::uint32_t middle =
        split(volume, begin, end, begin + static_cast<std::uint32_t>(point_tree_left_count(count)), keys);
    const std::uint32_t left = node_index + 1;
    const std::uint32_t right = left + static_cast<std::uint32_t>(point_tree_node_count(middle - begin));
    node.right_child = right;
    build(left, begin, middle, keys);
    build(right, middle, end, keys);
  }

  // Orders a leaf's points so each group of kLeafGroupPoints lanes lies close together: halved
  // along the widest slab at a whole number of groups, and each half again, down to one group (the
  // query settles a group from its moments where the whole leaf is too wide for its own).
  void order_groups(const geometry::Kdop14& volume, std::uint32_t begin, std::uint32_t end, SplitKeys& keys) {
    const std::uint32_t count = end - begin;
    if (count <= tables::kLeafGroupPoints) {
      return;
    }
    const std::uint32_t groups = (count + tables::kLeafGroupPoints - 1) / tables::kLeafGroupPoints;
    const std::uint32_t middle = split(volume, begin, end, begin + tables::kLeafGroupPoints * ((groups + 1) / 2), keys);
    order_groups(volume_of(begin, middle), begin, middle, keys);
    order_groups(volume_of(middle, end), middle, end, keys);
  }

  geometry::Kdop14 volume_of(std::uint32_t begin, std::uint32_t end) const {
    geometry::Kdop14 volume = geometry::Kdop14::empty();
    for (std::uint32_t i = begin; i < end; ++i) {
      volume.add(to_vector(points_[tree_.order[i]]));
    }
    return volume;
  }

  // Orders order[begin, end) so the points below `middle` are the lower ones along the widest slab.
  // `keys` holds at least end - begin.
  std::uint32_t split(const geometry::Kdop14& volume, std::uint32_t begin, std::uint32_t end, std::uint32_t middle,
                      SplitKeys& keys) {
    std::size_t widest = 0;
    double widest_extent = -1.0;
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      const double extent = (volume.max[slab] - volume.min[slab]) / geometry::kKdopSlabLength[slab];
      if (extent > widest_extent) {
        widest_extent = extent;
        widest = slab;
      }
    }
    const auto& direction = geometry::kKdopSlabDirections[widest];
    // Each point's key computed once and kept beside its index: nth_element compares each element
    // many times. Ties broken by index make the halves well defined; nth_element is deterministic,
    // so the same build of the generator gives the same order every time.
    keys.resize(end - begin);
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t index = tree_.order[i];
      const tables::PackedPoint& point = points_[index];
      const double projection = direction[0] * double{point.x_mm} + direction[1] * double{point.y_mm} +
                                direction[2] * double{point.z_mm};
      keys[i - begin] = {projection, index};
    }
    std::nth_element(keys.begin(), keys.begin() + (middle - begin), keys.begin() + (end - begin));
    for (std::uint32_t i = begin; i < end; ++i) {
      tree_.order[i] = keys[i - begin].second;
    }
    return middle;
  }

 private:
  const std::vector<tables::PackedPoint>& points_;
  PointTree& tree_;
};

}  // namespace

std::uint64_t point_tree_left_count(std::uint64_t count) {
  const std::uint64_t leaves = (count + tables::kMaxLeafPoints - 1) / tables::kMaxLeafPoints;
  return tables::kMaxLeafPoints * (leaves / 2);
}

std::uint64_t point_tree_node_count(std::uint64_t count) {
  if (count <= tables::kMaxLeafPoints) {
    return 1;
  }
  const std::uint64_t left = point_tree_left_count(count);
  return 1 + point_tree_node_count(left) + point_tree_node_count(count - left);
}

PointTree build_point_tree(const std::vector<tables::PackedPoint>& points, unsigned threads) {
  PointTree tree;
  const auto count = static_cast<std::uint32_t>(points.size());
  tree.order.resize(count);
  std::iota(tree.order.begin(), tree.order.end(), 0u);
  tree.nodes.resize(point_tree_node_count(count));
  TreeBuilder builder(points, tree);
  SplitKeys keys(count);
  if (threads <= 1 || count <= tables::kMaxLeafPoints) {
    builder.build(0, 0, count, keys);
    return tree;
  }
  // The root by hand, then its two subtrees side by side: they touch disjoint slots.
  geometry::Kdop14 volume = geometry::Kdop14::empty();
  for (const tables::PackedPoint& point : points) {
    volume.add(to_vector(point));
  }
  const std::uint32_t middle =
      builder.split(volume, 0, count, static_cast<std::uint32_t>(point_tree_left_count(count)), keys);
  tables::BvhNode& root = tree.nodes[0];
  std::memset(&root, 0, sizeof(root));
  std::copy(volume.min.begin(), volume.min.end(), root.dop_min);
  std::copy(volume.max.begin(), volume.max.end(), root.dop_max);
  root.right_child = 1 + static_cast<std::uint32_t>(point_tree_node_count(middle));
  SplitKeys left_keys(middle);
  std::thread left([&] { builder.build(1, 0, middle, left_keys); });
  builder.build(root.right_child, middle, count, keys);
  left.join();
  return tree;
}

}  // namespace stencil::tablegen
