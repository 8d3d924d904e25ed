// The points' 14-DOP tree (toolchain/tablegen/bvh_builder): every point in exactly one leaf, every
// leaf full but the last, every node's DOP holding everything below it, the left child right after
// its parent and the right child where the node counts say; the same tree whatever the threads.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/geometry/kdop14.hpp"
#include "firmware/core/tables/table_format.hpp"
#include "toolchain/tablegen/bvh_builder.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::tablegen;

namespace {

// `count` points on a lopsided spiral: no two share a coordinate, and every slab has extent.
std::vector<tables::PackedPoint> spiral(std::uint32_t count) {
  std::vector<tables::PackedPoint> points;
  for (std::uint32_t i = 0; i < count; ++i) {
    const double t = 0.37 * i;
    points.push_back({static_cast<float>(25.0 + 0.02 * i * std::cos(t)), static_cast<float>(12.0 + 0.01 * i * std::sin(t)),
                      static_cast<float>(0.003 * i)});
  }
  return points;
}

// Walks the subtree at `index`: each point's leaves counted, each leaf's size in depth-first order.
std::uint32_t check_subtree(const PointTree& tree, std::uint32_t index,
                            std::vector<int>& seen, std::vector<std::uint32_t>& leaf_sizes) {
  const tables::BvhNode& node = tree.nodes[index];
  std::uint32_t below = 0;
  if (node.point_count > 0) {
    leaf_sizes.push_back(node.point_count);
    for (std::uint32_t slot = node.first_point; slot < node.first_point + node.point_count; ++slot) {
      ++seen[tree.order[slot]];
    }
    below = node.point_count;
  } else {
    CHECK(node.right_child > index + 1);
    below = check_subtree(tree, index + 1, seen, leaf_sizes) +
            check_subtree(tree, node.right_child, seen, leaf_sizes);
  }
  return below;
}

// The point inside the node's DOP, by the table's own slab directions.
bool dop_holds(const tables::BvhNode& node, const tables::PackedPoint& p) {
  for (std::size_t slab = 0; slab < geometry::kKdopSlabCount; ++slab) {
    const auto& d = geometry::kKdopSlabDirections[slab];
    const double projection = d[0] * double{p.x_mm} + d[1] * double{p.y_mm} + d[2] * double{p.z_mm};
    if (projection < node.dop_min[slab] - 1e-9 || projection > node.dop_max[slab] + 1e-9) {
      return false;
    }
  }
  return true;
}

}  // namespace

TEST_GROUP(BvhBuilder){};

TEST(BvhBuilder, TheLeftChildTakesHalfItsLeavesWorth) {
  constexpr std::uint32_t L = tables::kMaxLeafPoints;
  CHECK_EQUAL(L, point_tree_left_count(L + 1));
  CHECK_EQUAL(L, point_tree_left_count(2 * L));
  CHECK_EQUAL(L, point_tree_left_count(3 * L));          // three leaves: one left, two right
  CHECK_EQUAL(2 * L, point_tree_left_count(3 * L + 1));  // four leaves: two and two
}

TEST(BvhBuilder, NodeCountsFollowTheSplit) {
  constexpr std::uint32_t L = tables::kMaxLeafPoints;
  CHECK_EQUAL(1U, point_tree_node_count(1));
  CHECK_EQUAL(1U, point_tree_node_count(L));
  CHECK_EQUAL(3U, point_tree_node_count(L + 1));
  CHECK_EQUAL(5U, point_tree_node_count(3 * L));
  CHECK_EQUAL(7U, point_tree_node_count(4 * L));
}

TEST(BvhBuilder, EveryPointIsInOneFullLeafAndInsideEveryDopAboveIt) {
  const std::vector<tables::PackedPoint> points = spiral(1000);
  const PointTree tree = build_point_tree(points, 1);
  CHECK_EQUAL(point_tree_node_count(points.size()), tree.nodes.size());
  CHECK_EQUAL(points.size(), tree.order.size());
  std::vector<int> seen(points.size(), 0);
  std::vector<std::uint32_t> leaf_sizes;
  CHECK_EQUAL(1000U, check_subtree(tree, 0, seen, leaf_sizes));
  CHECK(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  // Leaves in depth-first order: all full but the last (1000 = 15 * 64 + 40).
  static_assert(tables::kMaxLeafPoints == 64, "the counts below are for leaves of 64 points");
  CHECK_EQUAL(16U, leaf_sizes.size());
  for (std::size_t i = 0; i + 1 < leaf_sizes.size(); ++i) {
    CHECK_EQUAL(tables::kMaxLeafPoints, leaf_sizes[i]);
  }
  CHECK_EQUAL(40U, leaf_sizes.back());
  // The root's DOP holds every point; each leaf's DOP holds its own.
  for (const tables::PackedPoint& p : points) {
    CHECK(dop_holds(tree.nodes[0], p));
  }
  for (const tables::BvhNode& node : tree.nodes) {
    for (std::uint32_t slot = node.first_point; slot < node.first_point + node.point_count; ++slot) {
      CHECK(dop_holds(node, points[tree.order[slot]]));
    }
  }
}

TEST(BvhBuilder, TheLowerHalfAlongTheWidestSlabGoesLeft) {
  // Two leaves' worth of points along x only: the root splits them at x's median, the lower
  // half to the left.
  constexpr int kCount = 2 * static_cast<int>(tables::kMaxLeafPoints);
  std::vector<tables::PackedPoint> points;
  for (int i = kCount - 1; i >= 0; --i) {
    points.push_back({static_cast<float>(i), 0.0f, 0.0f});
  }
  const PointTree tree = build_point_tree(points, 1);
  CHECK_EQUAL(3U, tree.nodes.size());
  const tables::BvhNode& left = tree.nodes[1];
  for (std::uint32_t slot = left.first_point; slot < left.first_point + left.point_count; ++slot) {
    CHECK(points[tree.order[slot]].x_mm < static_cast<float>(kCount / 2));
  }
}

TEST(BvhBuilder, TheTreeIsTheSameWhateverTheThreads) {
  const std::vector<tables::PackedPoint> points = spiral(5000);
  const PointTree one = build_point_tree(points, 1);
  const PointTree two = build_point_tree(points, 2);
  CHECK(one.order == two.order);
  CHECK_EQUAL(one.nodes.size(), two.nodes.size());
  CHECK_EQUAL(0, std::memcmp(one.nodes.data(), two.nodes.data(), one.nodes.size() * sizeof(tables::BvhNode)));
}

TEST(BvhBuilder, EachGroupOfALeafsLanesIsAQuarterOfItsPointsAlongTheWidestSlab) {
  // One leaf of points along a line, given in scrambled order: its groups of kLeafGroupPoints
  // lanes are the lowest quarter, the next, and so on (each group in its own stretch of x).
  std::vector<tables::PackedPoint> points;
  for (std::uint32_t i = 0; i < tables::kMaxLeafPoints; ++i) {
    points.push_back({static_cast<float>((i * 37U) % tables::kMaxLeafPoints), 0.5F, 0.0F});
  }
  const PointTree tree = build_point_tree(points, 1);
  CHECK_EQUAL(1U, tree.nodes.size());
  for (std::uint32_t slot = 0; slot < tables::kMaxLeafPoints; ++slot) {
    const auto group = static_cast<float>(slot / tables::kLeafGroupPoints);
    const float x = points[tree.order[slot]].x_mm;
    CHECK(x >= group * static_cast<float>(tables::kLeafGroupPoints) &&
          x < (group + 1.0F) * static_cast<float>(tables::kLeafGroupPoints));
  }
}

TEST(BvhBuilder, AShortLeafHasWholeGroupsFirst) {
  // 40 points: two full groups, then the last 8; each group's points in their own stretch of x.
  constexpr std::uint32_t kCount = 40;
  std::vector<tables::PackedPoint> points;
  for (std::uint32_t i = 0; i < kCount; ++i) {
    points.push_back({static_cast<float>((i * 17U) % kCount), 0.5F, 0.0F});
  }
  const PointTree tree = build_point_tree(points, 1);
  std::vector<float> low(3, 1e9F), high(3, -1e9F);
  for (std::uint32_t slot = 0; slot < kCount; ++slot) {
    const std::uint32_t group = slot / tables::kLeafGroupPoints;
    low[group] = std::min(low[group], points[tree.order[slot]].x_mm);
    high[group] = std::max(high[group], points[tree.order[slot]].x_mm);
  }
  CHECK(high[0] < low[1] || high[1] < low[0]);
  CHECK(high[0] < low[2] || high[2] < low[0]);
  CHECK(high[1] < low[2] || high[2] < low[1]);
  DOUBLES_EQUAL(7.0, double{high[2] - low[2]}, 0.0);  // the last 8 points: 8 consecutive x
}
