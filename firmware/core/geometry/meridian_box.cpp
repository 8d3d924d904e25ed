// Interval walk of the tool's BSP over a meridian box.
#include "firmware/core/geometry/meridian_box.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::geometry {
namespace {

using meridian_box_detail::Range;
using meridian_box_detail::function_range;
using meridian_box_detail::interior_range;

// Invalid: a NaN in the tree's numbers, which classify_meridian reports as a fault per point.
enum class Answer : std::uint8_t { True, False, Unknown, Invalid };

bool is_nan(const Range& range) { return std::isnan(range.low) || std::isnan(range.high); }

// The node's test over the whole box, as classify_meridian's evaluate decides it per point.
Answer evaluate(const ToolBsp& tool, const BspNode& node, const MeridianBox& box) {
  const ImplicitSurface& a = tool.surfaces[node.surface_a];
  switch (node.test) {
    case NodeTest::InsideBoundary: {  // -tolerance <= interior distance
      const Range inside = interior_range(a, box);
      if (is_nan(inside)) {
        return Answer::Invalid;
      }
      return -kSurfaceTolerance_mm <= inside.low ? Answer::True
             : -kSurfaceTolerance_mm <= inside.high ? Answer::Unknown
                                                    : Answer::False;
    }
    case NodeTest::BelowPartition: {  // f < 0
      const Range f = function_range(a, box);
      if (is_nan(f)) {
        return Answer::Invalid;
      }
      return f.high < 0.0 ? Answer::True : f.low < 0.0 ? Answer::Unknown : Answer::False;
    }
    case NodeTest::NearerThan: {  // interior distance to a <= interior distance to b
      const Range left = interior_range(a, box);
      const Range right = interior_range(tool.surfaces[node.surface_b], box);
      if (is_nan(left) || is_nan(right)) {
        return Answer::Invalid;
      }
      return left.high <= right.low ? Answer::True : left.low <= right.high ? Answer::Unknown : Answer::False;
    }
  }
  return Answer::Invalid;
}

constexpr BoxPart kMixedPart{BoxCover::Mixed, 0, 0.0};

// Where a walk over the box ended: a settled part, a partition plane that splits the box (at
// `node`), or Mixed.
struct Settled {
  BoxPart part;
  bool split;
  std::size_t node;
};

// Walks from `link` (reached from node `from`, or the root when from_root) with the box.
Settled settle(const ToolBsp& tool, const MeridianBox& box, BspLink link, std::size_t from, bool from_root,
               bool may_split) {
  const Settled mixed{kMixedPart, false, 0};
  // A box across a boundary test whose false side is the outside of the tool is still settled if
  // its true side leads, for the whole box, to the region of that same surface: the per-point test
  // is then the region's own depth against the tolerance (see RegionOrOutside).
  bool straddles_boundary = false;
  std::uint8_t boundary_surface = 0;
  std::size_t node_index = from;
  for (std::size_t step = 0; step <= tool.node_count; ++step) {
    switch (link.kind) {
      case BspLink::Kind::Outside:
        return straddles_boundary ? mixed : Settled{{BoxCover::Outside, 0, 0.0}, false, 0};
      case BspLink::Kind::Region: {
        if (link.index >= tool.region_count || tool.regions[link.index].surface >= tool.surface_count) {
          return mixed;
        }
        const double deepest = interior_range(tool.surfaces[tool.regions[link.index].surface], box).high;
        if (!straddles_boundary) {
          return {{BoxCover::Region, link.index, deepest}, false, 0};
        }
        return tool.regions[link.index].surface == boundary_surface
                   ? Settled{{BoxCover::RegionOrOutside, link.index, deepest}, false, 0}
                   : mixed;
      }
      case BspLink::Kind::Node:
        // Forward only, as in classify_meridian.
        if ((!from_root || step > 0) && link.index <= node_index) {
          return mixed;
        }
        if (link.index >= tool.node_count) {
          return mixed;
        }
        node_index = link.index;
        break;
      default:
        return mixed;
    }
    const BspNode& node = tool.nodes[node_index];
    if (node.surface_a >= tool.surface_count ||
        (node.test == NodeTest::NearerThan && node.surface_b >= tool.surface_count)) {
      return mixed;
    }
    Answer answer = evaluate(tool, node, box);
    if (answer == Answer::Invalid) {
      return mixed;
    }
    if (answer == Answer::Unknown) {
      if (node.test == NodeTest::BelowPartition && tool.surfaces[node.surface_a].kind == SurfaceKind::PlaneZ &&
          may_split && !straddles_boundary) {
        return {kMixedPart, true, node_index};
      }
      if (straddles_boundary || node.test != NodeTest::InsideBoundary ||
          node.when_false.kind != BspLink::Kind::Outside) {
        return mixed;
      }
      straddles_boundary = true;
      boundary_surface = node.surface_a;
      answer = Answer::True;
    }
    link = answer == Answer::True ? node.when_true : node.when_false;
  }
  return mixed;
}

BoxClassification whole(const BoxPart& part) { return {part.cover, part.region, part.deepest_bound_mm, 0.0, {}, {}}; }

}  // namespace

BoxClassification classify_meridian_box(const ToolBsp& tool, const MeridianBox& box) {
  const BoxClassification mixed = whole(kMixedPart);
  // Anything classify_meridian would call a fault is left to it, point by point.
  if (tool.node_count == 0 || tool.node_count > kMaxToolNodes || tool.surface_count > kMaxToolSurfaces ||
      tool.region_count > kMaxToolRegions || !std::isfinite(box.r_low_mm) || !std::isfinite(box.r_high_mm) ||
      !std::isfinite(box.z_low_mm) || !std::isfinite(box.z_high_mm) || !(box.r_low_mm >= 0.0) ||
      !(box.r_low_mm <= box.r_high_mm) || !(box.z_low_mm <= box.z_high_mm)) {
    return mixed;
  }
  const Settled root = settle(tool, box, {BspLink::Kind::Node, 0}, 0, true, true);
  if (!root.split) {
    return whole(root.part);
  }
  // The box straddles a plane z = c that partitions the tree: settle each side with the whole box
  // (a bound for the points on that side), once, with no further split.
  const BspNode& node = tool.nodes[root.node];
  const Settled below = settle(tool, box, node.when_true, root.node, false, false);
  const Settled above = settle(tool, box, node.when_false, root.node, false, false);
  if (below.part.cover == BoxCover::Mixed || above.part.cover == BoxCover::Mixed) {
    return mixed;
  }
  return {BoxCover::SplitAtZ,
          0,
          std::max(below.part.deepest_bound_mm, above.part.deepest_bound_mm),
          tool.surfaces[node.surface_a].center_z_mm,
          below.part,
          above.part};
}

double region_deepest_bound(const ToolBsp& tool, std::uint8_t region, const MeridianBox& box) {
  return interior_range(tool.surfaces[tool.regions[region].surface], box).high;
}

}  // namespace stencil::geometry
