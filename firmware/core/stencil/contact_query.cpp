// The query: the tool's 14-DOP against the points' tree, then each nearby point through the tool BSP.
#include "firmware/core/stencil/contact_query.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <Eigen/Geometry>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "firmware/core/geometry/kdop14.hpp"
#include "firmware/core/geometry/meridian_box.hpp"
#include "firmware/core/geometry/tool_bound.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/geometry/upright_tool.hpp"
#include "firmware/core/stencil/leaf_contacts.hpp"

namespace stencil::engine {
namespace {

enum class Walk : std::uint8_t { Finished, Stopped, BadTree };

bool pose_is_usable(const ToolPose& pose) {
  return pose.tip_mm.allFinite() && pose.axis.allFinite() && std::abs(pose.axis.squaredNorm() - 1.0) < 1e-9;
}

// Whether the tool's volume and the node's 14-DOP overlap on every slab. With AVX2, the seven
// slabs as two overlapping runs of four (slabs 0-3 and 3-6), all compared at once and without a
// branch per slab: the walk tests every node it meets, most of them overlapping (deep contact),
// where the loop would run all seven slabs. The same comparisons, so the same answer.
bool overlaps_node(const geometry::Kdop14& volume, const tables::BvhNode& node) {
  static_assert(geometry::kKdopSlabCount == 7);
#if defined(__AVX2__)
  const auto separated = [&](std::size_t first) {
    const __m256d below = _mm256_cmp_pd(_mm256_loadu_pd(volume.min.data() + first),
                                        _mm256_loadu_pd(node.dop_max + first), _CMP_GT_OQ);
    const __m256d above = _mm256_cmp_pd(_mm256_loadu_pd(node.dop_min + first),
                                        _mm256_loadu_pd(volume.max.data() + first), _CMP_GT_OQ);
    return _mm256_or_pd(below, above);
  };
  return _mm256_movemask_pd(_mm256_or_pd(separated(0), separated(3))) == 0;
#else
  for (std::size_t slab = 0; slab < geometry::kKdopSlabCount; ++slab) {
    if (volume.min[slab] > node.dop_max[slab] || node.dop_min[slab] > volume.max[slab]) {
      return false;
    }
  }
  return true;
#endif
}

// Walks the points' tree for the tool at `pose`. Nodes are culled by the tool's 14-DOP and, for the
// upright tool of the 3-axis mill, by its outline (the envelope's DOP is loose around a ball's
// end), except under a node the tool tree settles (walk_settled culls by depth alone). For the
// upright tool each remaining leaf is taken as a whole, its points' depths and escape directions
// computed lane-wise: from one region's surface when the leaf's box lies in that region or just
// straddles its boundary (no walk of the tool tree per point), from the two sides' regions when it
// straddles a partition plane, point by point through the tool tree when it straddles other tests,
// skipped when the box is wholly outside. A leaf in one region (or in it or outside), or split
// between two at a plane, goes bound (bind_leaf) to visit_region_leaf(cover, leaf), which loads and
// settles its lanes itself (the query computes its force in the same pass) and answers a LeafVisit;
// a mixed one goes settled to visit_leaf. For any other axis each point goes through
// classify_at_pose and visit_point(index, classification) gets those in the tool or on its surface
// (and the leaf's block, for its normal). visit_point and visit_leaf stop the walk by returning
// false. When only penetrating points are wanted, a leaf whose box lies wholly deeper than the
// tolerance in one region, and every leaf under a node whose box does, goes first to
// visit_deep_leaf (below); a node whose box the tool tree settles in one region, or splits at a
// plane into two settled sides, has its subtree walked by that answer (walk_settled, walk_split)
// with no further walk of the tool tree. Iterative: fixed stacks as deep as the loader allows trees
// to be (one for the nodes not settled by an ancestor, one for a split subtree's, one for a settled
// subtree's), and a budget of the tree's node count for the nodes and the leaves taken whole, so
// tables the loader would refuse cannot make it loop.
enum class Wanted : std::uint8_t {
  Penetrating,  // only points deeper than the tolerance matter (force, legality)
  InTool,       // points on the surface matter too (touched triangles)
};

// What a visitor of a leaf tells the walk.
enum class LeafVisit : std::uint8_t {
  Continue,
  Stop,
  Fault,
  LoadPoints,  // (visit_deep_leaf) the block's own numbers do not settle it: visit its points after all
};

// A leaf wholly in one region (or in it or outside), or split between two at a plane, its lanes
// settled, given to visit_leaf: the visit of a settled leaf for walkers that want every lane's verdict.
template <typename VisitLeaf>
LeafVisit settle_region_leaf(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover,
                             LeafContacts& leaf, VisitLeaf& visit_leaf) {
  load_lanes(leaf);
  const bool finite = cover.cover == geometry::BoxCover::SplitAtZ
                          ? split_leaf_contacts(tool, cover, leaf)
                          : region_leaf_contacts(tool, cover.region, cover.cover == geometry::BoxCover::RegionOrOutside, leaf);
  if (!finite) {
    return LeafVisit::Fault;
  }
  return visit_leaf(leaf) ? LeafVisit::Continue : LeafVisit::Stop;
}

// A leaf or node whose deepest point cannot be deeper than the tolerance (half of it, so that the
// lanes' rounding cannot matter) has only touching points, which only the touched set wants.
bool shallower_than_penetration(double deepest_bound_mm) {
  return deepest_bound_mm < 0.5 * geometry::kSurfaceTolerance_mm;
}

// The leaf blocks of the subtree under node `index`: its leftmost leaf's to its rightmost leaf's.
// The loader holds the nodes in the walk's order and the leaves numbered in it, so every leaf of
// the subtree, and no other, is in that run. False for a tree the loader would have refused.
struct LeafRun {
  std::uint32_t first;
  std::uint32_t last;
};
bool leaves_below(const tables::PartTables& part, std::uint32_t index, LeafRun& run) {
  std::uint32_t leftmost = index;
  std::uint32_t rightmost = index;
  for (std::uint32_t step = 0; step <= tables::kMaxTreeDepth; ++step) {
    if (leftmost >= part.node_count() || rightmost >= part.node_count()) {
      return false;
    }
    const tables::BvhNode& left = part.nodes[leftmost];
    const tables::BvhNode& right = part.nodes[rightmost];
    if (left.point_count > 0 && right.point_count > 0) {
      run = {left.leaf, right.leaf};
      return run.first <= run.last && run.last < part.leaf_count();
    }
    leftmost = left.point_count > 0 ? leftmost : leftmost + 1;
    rightmost = right.point_count > 0 ? rightmost : right.right_child;
  }
  return false;
}

// A leaf settled in one region whose shallowest point (by its box, or its subtree's) is deeper than
// the tolerance has every point penetrating, all in that region: when only penetrating points are
// wanted, the walk gives it to visit_deep_leaf(cover, block) unloaded, which settles it from the
// block's own numbers (its count, sphere and moments) or answers LoadPoints, and the walk then
// binds it and gives it to visit_region_leaf as any leaf in one region.
template <typename VisitPoint, typename VisitLeaf, typename VisitRegionLeaf, typename VisitDeepLeaf>
Walk walk_points_in_tool(const tables::PartTables& part, const geometry::ToolBsp& tool, const ToolPose& pose,
                         Wanted wanted, VisitPoint&& visit_point, VisitLeaf&& visit_leaf,
                         VisitRegionLeaf&& visit_region_leaf, VisitDeepLeaf&& visit_deep_leaf) {
  const geometry::Kdop14 volume = geometry::tool_kdop(tool.envelope, pose.tip_mm, pose.axis);
  const bool upright = pose.axis == Eigen::Vector3d::UnitZ();
  std::array<std::uint32_t, tables::kMaxTreeDepth + 1> stack;  // nodes not settled by an ancestor
  std::size_t size = 0;
  stack[size++] = 0;
  // Nodes the walk may still take, popped or as leaves of a wholly deep run: in a tree each node is
  // taken once at most, so tables with a link back up the tree (which the loader refuses) end the
  // walk as a bad tree instead of looping, and all the walk's loops together take at most the node
  // count of steps.
  std::uint32_t budget = part.node_count();
  LeafContacts leaf;
  // The tip split for the lanes, once a walk, and only when a leaf is met (a query in free space
  // meets none).
  LeafTip tip{};
  bool tip_split = false;
  const auto bind_to = [&](const tables::LeafBlock& block) {
    if (!tip_split) {
      tip = leaf_tip(pose.tip_mm);
      tip_split = true;
    }
    bind_leaf(part, block, tip, leaf);
  };
  // The cover of the node classify_meridian_box last took.
  geometry::BoxClassification cover{geometry::BoxCover::Mixed, 0, 0.0, 0.0, {}, {}};
  // A deep leaf: settled by visit_deep_leaf from its block, or where that cannot, by its points.
  const auto visit_deep = [&](const geometry::BoxClassification& deep_cover, const tables::LeafBlock& block) {
    const LeafVisit visit = visit_deep_leaf(deep_cover, block);
    if (visit != LeafVisit::LoadPoints) {
      return visit;
    }
    bind_to(block);
    return visit_region_leaf(deep_cover, leaf);
  };
  // The leaf block of leaf node `node`, or nullptr for a leaf the loader would have refused.
  const auto block_of = [&](const tables::BvhNode& node) -> const tables::LeafBlock* {
    if (node.point_count > tables::kMaxLeafPoints || node.first_point > part.point_count() ||
        node.point_count > part.point_count() - node.first_point || node.leaf >= part.leaf_count() ||
        part.leaves[node.leaf].first_point != node.first_point ||
        part.leaves[node.leaf].point_count != node.point_count) {
      return nullptr;
    }
    return &part.leaves[node.leaf];
  };
  // Every leaf of the subtree under node `index`, all of whose points are deep (a run of leaf
  // blocks, numbered in the walk's order), to visit_deep in that order, with no box below this one
  // looked at: each with the subtree's cover and bound.
  const auto visit_deep_run = [&](std::uint32_t index, const geometry::BoxClassification& deep_cover) {
    LeafRun run{};
    if (!leaves_below(part, index, run) || run.last - run.first >= budget) {
      return LeafVisit::Fault;
    }
    budget -= run.last - run.first + 1;  // leaves the walk takes whole, each once in a sound tree
    for (std::uint32_t leaf_index = run.first; leaf_index <= run.last; ++leaf_index) {
      const tables::LeafBlock& block = part.leaves[leaf_index];
      if (block.point_count == 0 || block.point_count > tables::kMaxLeafPoints ||
          block.first_point > part.point_count() || block.point_count > part.point_count() - block.first_point) {
        return LeafVisit::Fault;  // a block the loader would have refused
      }
      const LeafVisit visit = visit_deep(deep_cover, block);
      if (visit != LeafVisit::Continue) {
        return visit;
      }
    }
    return LeafVisit::Continue;
  };
  // The subtree under node `root` (its children, not itself), settled in `region` as `settled`
  // says (Region or RegionOrOutside), in the walk's order. Below a node whose box the upright
  // tool's tree settles so, every node is settled so too as far as penetrating points go: the
  // loader holds each node's DOP inside its parent's, so each point of the subtree either reaches
  // that region, its depth that of the region's surface, or is outside the tool, its depth there
  // below the tolerance. So when only penetrating points are wanted each node is taken by its DOP
  // and its depth from that surface alone: no walk of the tool tree, no outline test, the same
  // verdicts, depths and forces. Most nodes are told shallow, or between the thresholds (a node to
  // walk into), without region_depth_range's sqrts (UprightDepthSpan, the same answers). A loop of
  // its own, in the order the mixed walk's stack would take the subtree in, with nothing of that
  // walk's to carry. This rests on the loader's check of the DOPs (nodes.dop, "inside its parent's
  // DOP"): tables that did not pass the loader get no such promise. With `with_root`, the subtree
  // is `root` and all under it (walk_split's: a node settled by its parent's cover, not its own).
  const auto walk_settled = [&](std::uint32_t root, const tables::BvhNode& root_node, geometry::BoxCover settled,
                                std::uint8_t region, bool with_root) {
    const geometry::UprightDepthSpan span(tool, region, pose.tip_mm, 0.5 * geometry::kSurfaceTolerance_mm,
                                          geometry::kSurfaceTolerance_mm);
    geometry::BoxClassification settled_cover{settled, region, 0.0, 0.0, {}, {}};
    std::array<std::uint32_t, tables::kMaxTreeDepth + 1> below;  // its own stack
    std::size_t count = 0;
    if (with_root) {
      below[count++] = root;
    } else {
      below[count++] = root_node.right_child;
      below[count++] = root + 1;
    }
    while (count > 0) {
      const std::uint32_t index = below[--count];
      if (index >= part.node_count() || budget-- == 0) {
        return Walk::BadTree;
      }
      const tables::BvhNode& node = part.nodes[index];
      // No test against the tool's 14-DOP here: a box it would cull holds no point inside the tool,
      // so none deeper than the tolerance, and the depth span tells almost all of them shallow
      // (measured: of 526 nodes in the bench's deep contact, 58 outside the DOP, all shallow; in
      // the deep corner 30 of 828, 12 of them walked into): the same answers for less.
      const Eigen::Vector3d low(node.dop_min[0], node.dop_min[1], node.dop_min[2]);
      const Eigen::Vector3d high(node.dop_max[0], node.dop_max[1], node.dop_max[2]);
      const geometry::DepthSpan depth_span = span(low, high);
      if (depth_span == geometry::DepthSpan::Shallower) {
        continue;
      }
      if (depth_span == geometry::DepthSpan::Between && node.point_count == 0) {
        if (count + 2 > below.size()) {
          return Walk::BadTree;  // deeper than the loader allows
        }
        below[count++] = node.right_child;
        below[count++] = index + 1;
        continue;
      }
      double shallowest_mm = -1.0;  // no point is shallower (where known; NaN from a damaged surface)
      if (depth_span == geometry::DepthSpan::Between) {
        // A leaf not wholly deep: its bound only asks whether one of its points may be the
        // deepest, and one no less than the range's gives the same answer.
        settled_cover.deepest_bound_mm = span.deepest_bound(low, high);
      } else {
        const geometry::DepthRange range =
            geometry::region_depth_range(tool, region, geometry::upright_meridian_box(pose.tip_mm, low, high));
        if (shallower_than_penetration(range.deepest_mm)) {
          continue;
        }
        settled_cover.deepest_bound_mm = range.deepest_mm;
        shallowest_mm = range.shallowest_mm;
      }
      LeafVisit visit = LeafVisit::Continue;
      if (node.point_count > 0) {
        const tables::LeafBlock* block = block_of(node);
        if (block == nullptr) {
          return Walk::BadTree;
        }
        if (shallowest_mm > geometry::kSurfaceTolerance_mm) {  // false for NaN
          visit = visit_deep(settled_cover, *block);
        } else {
          bind_to(*block);
          visit = visit_region_leaf(settled_cover, leaf);
        }
      } else if (shallowest_mm > geometry::kSurfaceTolerance_mm) {
        visit = visit_deep_run(index, settled_cover);
      } else {
        if (count + 2 > below.size()) {
          return Walk::BadTree;
        }
        below[count++] = node.right_child;
        below[count++] = index + 1;
      }
      if (visit != LeafVisit::Continue) {
        return visit == LeafVisit::Stop ? Walk::Stopped : Walk::BadTree;
      }
    }
    return Walk::Finished;
  };
  // The subtree under node `root` (its children, not itself), whose box straddles the tool tree's
  // partition plane z = split.split_z_mm with each side settled (split.below, split.above). A box
  // inside the root's (the loader's DOP check) with its points on one side only is settled as that
  // side says, by the same argument as walk_settled's: each point below the plane reaches the
  // region `below` names for the whole root box (or is outside the tool, its depth there below the
  // tolerance), and likewise above. So such a node and all under it go to walk_settled, and a node
  // still across the plane keeps the root's two sides: a leaf goes to visit_region_leaf with the
  // root's cover, less any side it is shallow on (below), the lanes' verdicts the same; its depth
  // bound is the root's, larger, which only asks for a search of its deepest lane that finds the
  // same point; the walk goes into the others. The plane test is classify_meridian's
  // (BelowPartition: z - split < 0 below, on the box's lowest or highest z). Classifying each of
  // these nodes from the tree's root gave the same verdicts, depths and forces in the same order,
  // at about 250 instructions a node; most of the deep corner's boxes met the plane of a ball's
  // centre.
  const auto walk_split = [&](std::uint32_t root, const tables::BvhNode& root_node,
                              const geometry::BoxClassification& split) {
    // Each settled side's depths: a box shallower on a side has no penetrating point there (none
    // of its points reaching that side's region is as deep as half the tolerance, the others are
    // outside the tool), so that side is taken as outside the tool for it: the same lanes' verdicts
    // (depth 0 either way) and forces (0), without that surface's numbers. A box shallower on both
    // is skipped, with everything under it.
    const auto span_of = [&](const geometry::BoxPart& side) {
      return side.cover == geometry::BoxCover::Outside
                 ? std::nullopt
                 : std::optional<geometry::UprightDepthSpan>(std::in_place, tool, side.region, pose.tip_mm,
                                                             0.5 * geometry::kSurfaceTolerance_mm,
                                                             geometry::kSurfaceTolerance_mm);
    };
    const std::optional<geometry::UprightDepthSpan> below_span = span_of(split.below);
    const std::optional<geometry::UprightDepthSpan> above_span = span_of(split.above);
    geometry::BoxClassification leaf_cover = split;
    std::array<std::uint32_t, tables::kMaxTreeDepth + 1> across;  // its own stack
    std::size_t count = 0;
    across[count++] = root_node.right_child;
    across[count++] = root + 1;
    while (count > 0) {
      const std::uint32_t index = across[--count];
      if (index >= part.node_count()) {
        return Walk::BadTree;
      }
      const tables::BvhNode& node = part.nodes[index];
      const double below_low = (node.dop_min[2] - pose.tip_mm.z()) - split.split_z_mm;
      const double below_high = (node.dop_max[2] - pose.tip_mm.z()) - split.split_z_mm;
      if (below_high < 0.0 || below_low >= 0.0) {
        const geometry::BoxPart& side = below_high < 0.0 ? split.below : split.above;
        if (side.cover == geometry::BoxCover::Outside) {
          if (budget-- == 0) {
            return Walk::BadTree;
          }
          continue;
        }
        const Walk walk = walk_settled(index, node, side.cover, side.region, true);  // takes the node's budget
        if (walk != Walk::Finished) {
          return walk;
        }
        continue;
      }
      if (budget-- == 0) {
        return Walk::BadTree;
      }
      if (!(below_low < 0.0)) {
        return Walk::BadTree;  // a NaN low z across the plane: a box the loader would have refused
      }
      if (!overlaps_node(volume, node)) {
        continue;
      }
      const Eigen::Vector3d low(node.dop_min[0], node.dop_min[1], node.dop_min[2]);
      const Eigen::Vector3d high(node.dop_max[0], node.dop_max[1], node.dop_max[2]);
      const bool below_shallow = !below_span || (*below_span)(low, high) == geometry::DepthSpan::Shallower;
      const bool above_shallow = !above_span || (*above_span)(low, high) == geometry::DepthSpan::Shallower;
      if (below_shallow && above_shallow) {
        continue;
      }
      if (node.point_count > 0) {
        const tables::LeafBlock* block = block_of(node);
        if (block == nullptr) {
          return Walk::BadTree;
        }
        leaf_cover.below = below_shallow ? geometry::BoxPart{geometry::BoxCover::Outside, 0, 0.0} : split.below;
        leaf_cover.above = above_shallow ? geometry::BoxPart{geometry::BoxCover::Outside, 0, 0.0} : split.above;
        bind_to(*block);
        const LeafVisit visit = visit_region_leaf(leaf_cover, leaf);
        if (visit != LeafVisit::Continue) {
          return visit == LeafVisit::Stop ? Walk::Stopped : Walk::BadTree;
        }
        continue;
      }
      if (count + 2 > across.size()) {
        return Walk::BadTree;  // deeper than the loader allows
      }
      across[count++] = node.right_child;
      across[count++] = index + 1;
    }
    return Walk::Finished;
  };
  while (size > 0) {
    const std::uint32_t index = stack[--size];
    if (index >= part.node_count() || budget-- == 0) {
      return Walk::BadTree;
    }
    const tables::BvhNode& node = part.nodes[index];
    if (!overlaps_node(volume, node)) {
      continue;
    }
    const Eigen::Vector3d low(node.dop_min[0], node.dop_min[1], node.dop_min[2]);
    const Eigen::Vector3d high(node.dop_max[0], node.dop_max[1], node.dop_max[2]);
    if (upright && !geometry::upright_box_may_touch(tool, pose.tip_mm, low, high, 0.0)) {
      continue;
    }
    double shallowest_mm = -1.0;  // of a box in one region: no point is shallower (where known; NaN from a damaged surface)
    if (node.point_count > 0) {
      const tables::LeafBlock* block = block_of(node);
      if (block == nullptr) {
        return Walk::BadTree;
      }
      if (upright) {
        const geometry::MeridianBox box = geometry::upright_meridian_box(pose.tip_mm, low, high);
        cover = geometry::classify_meridian_box(tool, box);
        if (cover.cover == geometry::BoxCover::Outside ||
            (wanted == Wanted::Penetrating && cover.cover != geometry::BoxCover::Mixed &&
             shallower_than_penetration(cover.deepest_bound_mm))) {
          continue;
        }
        if (wanted == Wanted::Penetrating &&
            (cover.cover == geometry::BoxCover::Region || cover.cover == geometry::BoxCover::RegionOrOutside)) {
          shallowest_mm = geometry::region_depth_range(tool, cover.region, box).shallowest_mm;
        }
        LeafVisit visit = LeafVisit::Continue;
        if (wanted == Wanted::Penetrating && shallowest_mm > geometry::kSurfaceTolerance_mm) {  // false for NaN
          visit = visit_deep(cover, *block);
        } else {
          bind_to(*block);
          if (cover.cover == geometry::BoxCover::Region || cover.cover == geometry::BoxCover::RegionOrOutside ||
              cover.cover == geometry::BoxCover::SplitAtZ) {
            visit = visit_region_leaf(cover, leaf);
          } else {
            load_lanes(leaf);
            if (!mixed_leaf_contacts(tool, leaf)) {
              return Walk::BadTree;
            }
            visit = visit_leaf(leaf) ? LeafVisit::Continue : LeafVisit::Stop;
          }
        }
        if (visit != LeafVisit::Continue) {
          return visit == LeafVisit::Stop ? Walk::Stopped : Walk::BadTree;
        }
        continue;
      }
      for (std::uint32_t i = node.first_point; i < node.first_point + node.point_count; ++i) {
        const tables::PackedPoint& p = part.points[i];
        const Eigen::Vector3d point(p.x_mm, p.y_mm, p.z_mm);
        const geometry::PointClassification result = geometry::classify_at_pose(tool, pose.tip_mm, pose.axis, point);
        if (result.contact == geometry::PointContact::BadTree) {
          return Walk::BadTree;
        }
        if (result.contact != geometry::PointContact::Outside && !visit_point(i, result, *block)) {
          return Walk::Stopped;
        }
      }
      continue;
    }
    if (upright && wanted == Wanted::Penetrating) {
      const geometry::MeridianBox box = geometry::upright_meridian_box(pose.tip_mm, low, high);
      cover = geometry::classify_meridian_box(tool, box);
      if (cover.cover == geometry::BoxCover::Outside ||
          (cover.cover != geometry::BoxCover::Mixed && shallower_than_penetration(cover.deepest_bound_mm))) {
        continue;  // as each of its leaves would be
      }
      if (cover.cover == geometry::BoxCover::Region || cover.cover == geometry::BoxCover::RegionOrOutside) {
        // Every point below is deep, or the subtree is settled in the region.
        if (geometry::region_depth_range(tool, cover.region, box).shallowest_mm >
            geometry::kSurfaceTolerance_mm) {  // false for NaN
          const LeafVisit visit = visit_deep_run(index, cover);
          if (visit != LeafVisit::Continue) {
            return visit == LeafVisit::Stop ? Walk::Stopped : Walk::BadTree;
          }
          continue;
        }
        const Walk walk = walk_settled(index, node, cover.cover, cover.region, false);
        if (walk != Walk::Finished) {
          return walk;
        }
        continue;
      }
      if (cover.cover == geometry::BoxCover::SplitAtZ) {
        const Walk walk = walk_split(index, node, cover);
        if (walk != Walk::Finished) {
          return walk;
        }
        continue;
      }
    }
    if (size + 2 > stack.size()) {
      return Walk::BadTree;  // deeper than the loader allows: the tables were not loaded by it
    }
    stack[size++] = node.right_child;
    stack[size++] = index + 1;
  }
  return Walk::Finished;
}

// The pending search for the deepest point of leaves settled whole (visit_deep_leaf): the query
// counts and pushes such a leaf at once, but looks for its deepest point only after the walk, and
// only while the leaf's bound can still beat the deepest point found, best bound first; a full list
// makes room by settling its best leaf at once. 256 is past the deepest contact the bench measures
// (100 such leaves at 1e6 points in the deep corner).
inline constexpr std::size_t kMaxPendingDeepLeaves = 256;
struct PendingDeepLeaf {
  std::uint32_t leaf;
  std::uint8_t region;
  double deepest_bound_mm;
};

// The normal of `point`, of the leaf whose block is `block`.
Eigen::Vector3d normal_of(const tables::LeafBlock& block, std::uint32_t point) {
  const std::uint32_t lane = point - block.first_point;
  return {block.nx[lane], block.ny[lane], block.nz[lane]};
}

}  // namespace

ContactResult query_contacts(const tables::PartTables& part, const ToolPose& pose, const ContactParameters& parameters) {
  ContactResult result{QueryStatus::Ok, 0, 0.0, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  if (!pose_is_usable(pose)) {
    result.status = QueryStatus::BadInput;
    return result;
  }
  const double k_world = parameters.stiffness_n_per_device_mm * parameters.device_mm_per_world_mm;
  const Eigen::Vector3d centre = pose.tip_mm + parameters.compliance_centre_mm * pose.axis;
  Eigen::Vector3d force_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_sum = Eigen::Vector3d::Zero();
  // Whether a point (or a leaf of points from `first` on) this deep may be the deepest: deeper, or
  // as deep and earlier in the walk's order (the points' order), as the walk alone would pick it.
  const auto may_beat = [&](double depth, std::uint32_t first) {
    return depth > result.max_depth_mm ||
           (depth == result.max_depth_mm && result.max_depth_mm > 0.0 && first < result.deepest_point);
  };
  LeafContacts searched;
  std::optional<LeafTip> search_tip;  // split once, at the first search
  // A group of the leaf's lanes whose every point is shallower than the deepest found cannot beat
  // it, even on a tie: the search leaves it out.
  const auto search_deepest = [&](std::uint32_t leaf_index, std::uint8_t region) {
    if (!search_tip) {
      search_tip = leaf_tip(pose.tip_mm);
    }
    bind_leaf(part, part.leaves[leaf_index], *search_tip, searched);
    RegionLeafForce deepest{};
    if (!region_leaf_deepest(part.tool, region, result.max_depth_mm, searched, deepest)) {
      return false;
    }
    if (deepest.penetrating > 0 && may_beat(deepest.max_depth_mm, searched.first + deepest.deepest_lane)) {
      result.max_depth_mm = deepest.max_depth_mm;
      result.deepest_point = searched.first + deepest.deepest_lane;
    }
    return true;
  };
  std::array<PendingDeepLeaf, kMaxPendingDeepLeaves> pending_deep;
  std::size_t pending_count = 0;
  // Whether pending leaf a comes after b: a shallower bound, or as deep a bound and later in the
  // points' order (the tie goes to the earlier point). Bounds are never NaN: a NaN one is not pushed.
  const auto after = [](const PendingDeepLeaf& a, const PendingDeepLeaf& b) {
    return a.deepest_bound_mm < b.deepest_bound_mm ||
           (a.deepest_bound_mm == b.deepest_bound_mm && a.leaf > b.leaf);
  };
  // The pending leaf with the deepest bound. pending_count > 0.
  const auto best_pending = [&]() {
    std::size_t best = 0;
    for (std::size_t i = 1; i < pending_count; ++i) {
      best = after(pending_deep[best], pending_deep[i]) ? i : best;
    }
    return best;
  };
  // Takes pending leaf `best` off the list and searches it if it may still beat the deepest found
  // (once it cannot, it never can: the deepest only grows). False on a fault.
  const auto settle_pending = [&](std::size_t best) {
    const PendingDeepLeaf next = pending_deep[best];
    pending_deep[best] = pending_deep[--pending_count];
    return !may_beat(next.deepest_bound_mm, part.leaves[next.leaf].first_point) || search_deepest(next.leaf, next.region);
  };
  const auto count_depth = [&](std::uint32_t i, double depth) {
    ++result.penetrating_points;
    if (depth > result.max_depth_mm) {
      result.max_depth_mm = depth;
      result.deepest_point = i;
    }
  };
  const auto visit_point = [&](std::uint32_t i, const geometry::PointClassification& c, const tables::LeafBlock& block) {
    if (c.contact != geometry::PointContact::Penetrating) {
      return true;
    }
    count_depth(i, c.depth_mm);
    // The part pushes the tool out along the point's normal; the tool's own escape direction says
    // the same from the other side. Their average is robust where one of them is poor.
    Eigen::Vector3d direction = normal_of(block, i) - c.escape_direction;
    const double length = direction.norm();
    if (length < kNoDirection) {
      return true;  // the two disagree completely: this point gives no direction
    }
    direction /= length;
    const Eigen::Vector3d force = k_world * c.depth_mm * direction;
    const tables::PackedPoint& p = part.points[i];
    force_sum += force;
    torque_sum += (Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm) - centre).cross(force);
    return true;
  };
  // The same per point as visit_point, lane-wise over the leaf (single-precision sums in an order
  // fixed by the build, so the same inputs still give the same bits).
  const auto visit_leaf = [&](const LeafContacts& leaf) {
    if (leaf.penetrating == 0) {
      return true;
    }
    result.penetrating_points += leaf.penetrating;
    if (leaf.max_depth_mm > result.max_depth_mm) {
      result.max_depth_mm = leaf.max_depth_mm;
      result.deepest_point = leaf.first + leaf.deepest_lane;
    }
    const LeafForceSums sums = leaf_forces(leaf, k_world, parameters.compliance_centre_mm);
    force_sum += sums.force;
    torque_sum += sums.torque;
    return true;
  };
  // A leaf in one region, or split between two: its force in one pass over the lanes, and its
  // deepest lane searched only when the box's bound says one of its points may be deeper than the
  // deepest found so far.
  const auto visit_region_leaf = [&](const geometry::BoxClassification& cover, LeafContacts& leaf) {
    RegionLeafForce settled{};
    const bool find_deepest = cover.deepest_bound_mm > result.max_depth_mm;
    const bool finite =
        cover.cover == geometry::BoxCover::SplitAtZ
            ? split_leaf_force(part.tool, cover, find_deepest, k_world, parameters.compliance_centre_mm, leaf, settled)
            : region_leaf_force(part.tool, cover.region, cover.cover == geometry::BoxCover::RegionOrOutside,
                                find_deepest, k_world, parameters.compliance_centre_mm, leaf, settled);
    if (!finite) {
      return LeafVisit::Fault;
    }
    if (settled.penetrating == 0) {
      return LeafVisit::Continue;
    }
    result.penetrating_points += settled.penetrating;
    if (settled.max_depth_mm > result.max_depth_mm) {
      result.max_depth_mm = settled.max_depth_mm;
      result.deepest_point = leaf.first + settled.deepest_lane;
    }
    force_sum += settled.sums.force;
    torque_sum += settled.sums.torque;
    return LeafVisit::Continue;
  };
  // A leaf wholly deeper than the tolerance: every point counted, the force from its moments, its
  // deepest point looked for after the walk if its bound may beat what the walk found.
  const auto visit_deep_leaf = [&](const geometry::BoxClassification& cover, const tables::LeafBlock& block) {
    const geometry::ImplicitSurface& surface = part.tool.surfaces[part.tool.regions[cover.region].surface];
    const std::uint32_t leaf_index = static_cast<std::uint32_t>(&block - part.leaves);
    // Finite: the walk found the leaf deep from this surface's finite numbers, and the loader checked
    // the block's.
    const LeafMomentForce moment = leaf_moment_force(surface, block, pose.tip_mm, centre, k_world);
    if (!moment.settled) {
      return LeafVisit::LoadPoints;
    }
    force_sum += moment.force;
    torque_sum += moment.torque;
    const double bound = may_beat(cover.deepest_bound_mm, block.first_point)
                             ? std::min(cover.deepest_bound_mm, leaf_deepest_bound(surface, block, pose.tip_mm))
                             : cover.deepest_bound_mm;
    // A full list makes room by settling its best leaf (which also raises the deepest found, so
    // fewer leaves are pushed after it) rather than searching each leaf from then on.
    if (may_beat(bound, block.first_point) && pending_count == pending_deep.size() &&
        !settle_pending(best_pending())) {
      return LeafVisit::Fault;
    }
    if (may_beat(bound, block.first_point)) {
      pending_deep[pending_count++] = {leaf_index, cover.region, bound};
    }
    result.penetrating_points += block.point_count;
    return LeafVisit::Continue;
  };
  const Walk walk = walk_points_in_tool(part, part.tool, pose, Wanted::Penetrating, visit_point, visit_leaf,
                                        visit_region_leaf, visit_deep_leaf);
  if (walk == Walk::BadTree) {
    return {QueryStatus::BadTree, 0, 0.0, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  // The deep leaves' deepest points, best bound first, until no bound left can beat the deepest:
  // those that could still beat it when the walk ended (the others dropped first) in a heap by
  // `after`, a strict order, so the leaves are searched in the same order as by a scan for the
  // best each round (which took about 6,000 instructions of the bench's deep contact, its list
  // of about 60 leaves scanned about ten times).
  std::size_t kept = 0;
  for (std::size_t i = 0; i < pending_count; ++i) {
    if (may_beat(pending_deep[i].deepest_bound_mm, part.leaves[pending_deep[i].leaf].first_point)) {
      pending_deep[kept++] = pending_deep[i];
    }
  }
  pending_count = kept;
  const auto pending_end = [&] { return pending_deep.begin() + static_cast<std::ptrdiff_t>(pending_count); };
  std::make_heap(pending_deep.begin(), pending_end(), after);
  while (pending_count > 0 &&
         may_beat(pending_deep.front().deepest_bound_mm, part.leaves[pending_deep.front().leaf].first_point)) {
    std::pop_heap(pending_deep.begin(), pending_end(), after);
    const PendingDeepLeaf next = pending_deep[--pending_count];
    if (!search_deepest(next.leaf, next.region)) {
      return {QueryStatus::BadTree, 0, 0.0, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    }
  }
  const double magnitude = force_sum.norm();
  if (magnitude > 0.0) {
    const double scale = k_world * result.max_depth_mm / magnitude;
    result.force_n = scale * force_sum;
    result.torque_nmm = scale * torque_sum;
  }
  return result;
}

Legality check_legal(const tables::PartTables& part, const ToolPose& pose) {
  if (!pose_is_usable(pose)) {
    return Legality::Fault;
  }
  auto visit_leaf = [](const LeafContacts& leaf) { return leaf.penetrating == 0; };
  const Walk walk = walk_points_in_tool(
      part, part.tool, pose, Wanted::Penetrating,
      [](std::uint32_t, const geometry::PointClassification& c, const tables::LeafBlock&) {
        return c.contact != geometry::PointContact::Penetrating;
      },
      visit_leaf,
      [&](const geometry::BoxClassification& cover, LeafContacts& leaf) {
        return settle_region_leaf(part.tool, cover, leaf, visit_leaf);
      },
      [](const geometry::BoxClassification&, const tables::LeafBlock&) { return LeafVisit::Stop; });  // every point penetrates
  switch (walk) {
    case Walk::Finished:
      return Legality::Legal;
    case Walk::Stopped:
      return Legality::Illegal;
    case Walk::BadTree:
      break;
  }
  return Legality::Fault;
}

std::uint32_t mark_touched(const tables::PartTables& part, const geometry::ToolBsp& contact_tool, const ToolPose& pose,
                           double contact_tolerance_mm, TriangleSet& touched) {
  if (!pose_is_usable(pose)) {
    return 0;
  }
  const std::size_t before = touched.count();
  const ToolPose inflated{pose.tip_mm - contact_tolerance_mm * pose.axis, pose.axis};
  auto visit_leaf = [&](const LeafContacts& leaf) {
    for (std::uint32_t lane = 0; lane < leaf.count; ++lane) {
      if ((leaf.in_tool >> lane) & 1U) {
        touched.insert(part.triangle_ids[leaf.first + lane]);
      }
    }
    return true;
  };
  static_cast<void>(walk_points_in_tool(
      part, contact_tool, inflated, Wanted::InTool,
      [&](std::uint32_t i, const geometry::PointClassification&, const tables::LeafBlock&) {
        touched.insert(part.triangle_ids[i]);
        return true;
      },
      visit_leaf,
      [&](const geometry::BoxClassification& cover, LeafContacts& leaf) {
        return settle_region_leaf(contact_tool, cover, leaf, visit_leaf);
      },
      // Never called: the touched set wants the points on the surface too, so every leaf is visited.
      [](const geometry::BoxClassification&, const tables::LeafBlock&) { return LeafVisit::Fault; }));
  return static_cast<std::uint32_t>(touched.count() - before);
}

bool build_contact_tool(const geometry::ToolSpec& spec, double contact_tolerance_mm, geometry::ToolBsp& contact_tool) {
  geometry::ToolSpec inflated = spec;
  inflated.diameter_mm += 2.0 * contact_tolerance_mm;
  inflated.flute_length_mm += contact_tolerance_mm;
  inflated.corner_radius_mm += spec.kind == geometry::CutterKind::BullNose ? contact_tolerance_mm : 0.0;
  inflated.holder_diameter_mm += 2.0 * contact_tolerance_mm;
  inflated.holder_length_mm += contact_tolerance_mm;
  return geometry::build_tool_bsp(inflated, contact_tool).ok;
}

}  // namespace stencil::engine
