// A box's answer from the interval walk holds for every point in it, as classify_meridian says
// point by point; and small boxes are mostly settled, or the query would gain nothing.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "firmware/core/geometry/meridian_box.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "tests/support/sample_tools.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;
using stencil::test::kSampleTools;

namespace {

struct Tally {
  int boxes = 0;
  int settled = 0;
  int region_or_outside = 0;
  int split = 0;
  int wholly_penetrating = 0;  // sampled points of boxes whose shallowest depth is beyond the tolerance
};

// Checks the box's answer against classify_meridian at its corners and at random points in it.
void check_box(const ToolBsp& tool, const MeridianBox& box, std::mt19937_64& random, Tally& tally) {
  const BoxClassification answer = classify_meridian_box(tool, box);
  ++tally.boxes;
  tally.settled += answer.cover != BoxCover::Mixed ? 1 : 0;
  tally.region_or_outside += answer.cover == BoxCover::RegionOrOutside ? 1 : 0;
  tally.split += answer.cover == BoxCover::SplitAtZ ? 1 : 0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 24; ++i) {
    const double u = i < 4 ? static_cast<double>(i & 1) : unit(random);
    const double v = i < 4 ? static_cast<double>(i >> 1) : unit(random);
    const MeridianPoint point{box.r_low_mm + u * (box.r_high_mm - box.r_low_mm),
                              box.z_low_mm + v * (box.z_high_mm - box.z_low_mm)};
    const MeridianClassification truth = classify_meridian(tool, point);
    CHECK(truth.contact != PointContact::BadTree);
    BoxPart part{answer.cover, answer.region, answer.deepest_bound_mm};
    if (answer.cover == BoxCover::SplitAtZ) {
      part = point.z_mm - answer.split_z_mm < 0.0 ? answer.below : answer.above;
      CHECK(part.deepest_bound_mm <= answer.deepest_bound_mm);
    }
    switch (part.cover) {
      case BoxCover::Outside:
        CHECK(truth.contact == PointContact::Outside);
        break;
      case BoxCover::Region:
      case BoxCover::RegionOrOutside: {
        const ImplicitSurface& surface = tool.surfaces[tool.regions[part.region].surface];
        const double depth = interior_distance(surface, point);
        CHECK(depth <= part.deepest_bound_mm);
        // The range's shallow end: a box wholly beyond the tolerance has every point penetrating
        // (the query settles such a leaf without visiting its points).
        const DepthRange range = region_depth_range(tool, part.region, box);
        DOUBLES_EQUAL(region_deepest_bound(tool, part.region, box), range.deepest_mm, 0.0);
        CHECK(range.shallowest_mm <= depth);
        if (range.shallowest_mm > kSurfaceTolerance_mm) {
          ++tally.wholly_penetrating;
          CHECK(truth.contact == PointContact::Penetrating);
          LONGS_EQUAL(part.region, truth.region);
        }
        if (part.cover == BoxCover::Region) {
          CHECK(truth.contact != PointContact::Outside);
        }
        if (truth.contact == PointContact::Outside) {
          CHECK(depth < -kSurfaceTolerance_mm);  // outside exactly where the region's test fails
        } else {
          LONGS_EQUAL(part.region, truth.region);
          CHECK(depth >= -kSurfaceTolerance_mm);
        }
        break;
      }
      case BoxCover::SplitAtZ:
        FAIL("a side of a split is itself split");
        break;
      case BoxCover::Mixed:
        CHECK(answer.cover == BoxCover::Mixed);  // a split's sides are never Mixed
        break;
    }
  }
}

// A box of the meridian plane somewhere over the tool (out past the holder's side, from just
// below the tip to past its top), its size 10^(low_exponent + up to `decades`) mm.
struct RandomBox {
  MeridianBox box;
  double size;
};
RandomBox random_box(const ToolBsp& tool, std::mt19937_64& random, double low_exponent, double decades) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double reach = 1.2 * tool.envelope.holder_radius_mm;
  const double height = 1.1 * tool.envelope.total_length_mm;
  const double size = std::pow(10.0, low_exponent + decades * unit(random));
  const double r = reach * unit(random);
  const double z = -0.05 * height + height * unit(random);
  return {{r, r + size * unit(random), z, z + size * unit(random)}, size};
}

}  // namespace

TEST_GROUP(MeridianBox){};

TEST(MeridianBox, EverySettledBoxAgreesWithEachOfItsPointsAndSmallBoxesAreMostlySettled) {
  std::mt19937_64 random(2026);
  for (const auto& sample : kSampleTools) {
    ToolBsp tool{};
    CHECK(build_tool_bsp(sample.spec, tool).ok);
    Tally small;
    Tally large;
    for (int i = 0; i < 4000; ++i) {
      // Sizes from a micrometre to a few millimetres, like leaves of fine and coarse tables.
      const RandomBox sampled = random_box(tool, random, -3.0, 3.5);
      check_box(tool, sampled.box, random, sampled.size < 0.2 ? small : large);
    }
    // Boxes of a leaf's size (well under the tool's features) rarely straddle two tests at once.
    CHECK_TEXT(small.settled > 19 * small.boxes / 20, sample.name);
    CHECK_TEXT(small.region_or_outside > 0, sample.name);
    CHECK_TEXT(small.wholly_penetrating > 0, sample.name);  // the check above is not vacuous
  }
}

TEST(MeridianBox, BoxesOnTheAxisAndAtTheTipAreSettledCorrectly) {
  std::mt19937_64 random(5);
  Tally tally;
  for (const auto& sample : kSampleTools) {
    ToolBsp tool{};
    CHECK(build_tool_bsp(sample.spec, tool).ok);
    for (const double size : {1e-6, 1e-3, 0.1}) {
      check_box(tool, {0.0, size, 0.0, size}, random, tally);          // the tip on the axis
      check_box(tool, {0.0, size, -size, 0.0}, random, tally);         // just below the tip
      check_box(tool, {0.0, size, 0.5, 0.5 + size}, random, tally);    // inside, on the axis
    }
  }
  CHECK(tally.settled > 0);
}

TEST(MeridianBox, ABoxAcrossTheBallsEquatorIsSplitThere) {
  // Ball d3: the tree parts the hemisphere (below z = 1.5) from the flutes' cylinder above it.
  std::mt19937_64 random(3);
  ToolBsp tool{};
  CHECK(build_tool_bsp(kSampleTools[2].spec, tool).ok);
  for (const double r : {0.2, 0.7, 1.45, 1.49}) {
    const MeridianBox box{r, r + 0.02, 1.49, 1.51};
    const BoxClassification answer = classify_meridian_box(tool, box);
    CHECK(answer.cover == BoxCover::SplitAtZ);
    DOUBLES_EQUAL(1.5, answer.split_z_mm, 0.0);
    Tally tally;
    check_box(tool, box, random, tally);
  }
}

TEST(MeridianBox, ADamagedTreeOrABadBoxIsLeftToThePointByPointWalk) {
  ToolBsp tool{};
  CHECK(build_tool_bsp(kSampleTools[2].spec, tool).ok);
  const MeridianBox inside{0.0, 0.01, 0.5, 0.51};
  CHECK(classify_meridian_box(tool, inside).cover == BoxCover::Region);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(classify_meridian_box(tool, {nan, 0.01, 0.5, 0.51}).cover == BoxCover::Mixed);
  CHECK(classify_meridian_box(tool, {0.02, 0.01, 0.5, 0.51}).cover == BoxCover::Mixed);   // low > high
  CHECK(classify_meridian_box(tool, {-0.1, 0.01, 0.5, 0.51}).cover == BoxCover::Mixed);   // r < 0
  ToolBsp broken = tool;
  broken.nodes[0].when_true = {BspLink::Kind::Node, 0};  // a backward link
  broken.nodes[0].when_false = {BspLink::Kind::Node, 0};
  CHECK(classify_meridian_box(broken, inside).cover == BoxCover::Mixed);
  broken = tool;
  for (auto& surface : broken.surfaces) {
    surface.radius_mm = nan;
    surface.center_z_mm = nan;
  }
  CHECK(classify_meridian_box(broken, inside).cover == BoxCover::Mixed);
  // One NaN partition plane (the ball's equator) across the box: a fault per point, so Mixed, never
  // a split at NaN.
  for (std::uint8_t i = 0; i < tool.surface_count; ++i) {
    if (tool.surfaces[i].kind == SurfaceKind::PlaneZ && tool.surfaces[i].center_z_mm == 1.5) {
      broken = tool;
      broken.surfaces[i].center_z_mm = nan;
      CHECK(classify_meridian_box(broken, {2.0, 2.1, 0.5, 0.6}).cover == BoxCover::Mixed);
      CHECK(classify_meridian_box(broken, {0.2, 0.3, 1.49, 1.51}).cover == BoxCover::Mixed);
      CHECK(classify_meridian(broken, {2.05, 0.55}).contact == PointContact::BadTree);
    }
  }
  broken = tool;
  broken.node_count = 200;
  CHECK(classify_meridian_box(broken, inside).cover == BoxCover::Mixed);
}

TEST(MeridianBox, TheUprightBoxHoldsEveryPointsRadiusAndHeight) {
  std::mt19937_64 random(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d tip(20.0 + 5.0 * unit(random), 10.0 + 5.0 * unit(random), 3.0 + unit(random));
    // Boxes around the axis, beside it and far from it, down to a micrometre across.
    const double size = std::pow(10.0, -3.0 + 2.5 * (0.5 + 0.5 * unit(random)));
    const Eigen::Vector3d low = tip + Eigen::Vector3d(2.0 * unit(random), 2.0 * unit(random), 2.0 * unit(random));
    const Eigen::Vector3d high = low + size * Eigen::Vector3d(0.5 + 0.5 * unit(random), 0.5 + 0.5 * unit(random), 1.0);
    const MeridianBox box = upright_meridian_box(tip, low, high);
    // The corners, the point of the footprint nearest the axis, and random points inside.
    const Eigen::Vector3d nearest(std::clamp(tip.x(), low.x(), high.x()), std::clamp(tip.y(), low.y(), high.y()),
                                  low.z());
    for (int sample = 0; sample < 16; ++sample) {
      Eigen::Vector3d p;
      if (sample < 8) {
        p = {(sample & 1) ? high.x() : low.x(), (sample & 2) ? high.y() : low.y(), (sample & 4) ? high.z() : low.z()};
      } else if (sample == 8) {
        p = nearest;
      } else {
        const Eigen::Vector3d u(0.5 + 0.5 * unit(random), 0.5 + 0.5 * unit(random), 0.5 + 0.5 * unit(random));
        p = low + u.cwiseProduct(high - low);
      }
      const Eigen::Vector3d local = p - tip;
      const double r = std::sqrt(local.x() * local.x() + local.y() * local.y());
      CHECK(box.r_low_mm <= r && r <= box.r_high_mm);
      CHECK(box.z_low_mm <= local.z() && local.z() <= box.z_high_mm);
    }
    // And it is tight: the nearest point's radius is the lower bound.
    const Eigen::Vector3d near_local = nearest - tip;
    DOUBLES_EQUAL(std::sqrt(near_local.x() * near_local.x() + near_local.y() * near_local.y()), box.r_low_mm, 1e-12);
  }
}

// The query keeps a settled box's region for every box inside it (the points' tree below a
// settled node): each such box that is not wholly outside is settled in that same region, Region
// below Region, and region_deepest_bound gives it the bound its own classification would.
TEST(MeridianBox, ABoxInsideASettledOneIsSettledInTheSameRegionWithTheSameBound) {
  std::mt19937_64 random(30);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& sample : kSampleTools) {
    ToolBsp tool{};
    CHECK(build_tool_bsp(sample.spec, tool).ok);
    int inner_settled = 0;
    for (int i = 0; i < 4000; ++i) {
      const MeridianBox box = random_box(tool, random, -2.0, 2.5).box;
      const BoxClassification outer = classify_meridian_box(tool, box);
      if (outer.cover != BoxCover::Region && outer.cover != BoxCover::RegionOrOutside) {
        continue;
      }
      DOUBLES_EQUAL(outer.deepest_bound_mm, region_deepest_bound(tool, outer.region, box), 0.0);
      for (int j = 0; j < 4; ++j) {
        const double r_low = box.r_low_mm + (box.r_high_mm - box.r_low_mm) * unit(random);
        const double z_low = box.z_low_mm + (box.z_high_mm - box.z_low_mm) * unit(random);
        const MeridianBox inner{r_low, r_low + (box.r_high_mm - r_low) * unit(random), z_low,
                                z_low + (box.z_high_mm - z_low) * unit(random)};
        const BoxClassification own = classify_meridian_box(tool, inner);
        CHECK(own.cover != BoxCover::Mixed && own.cover != BoxCover::SplitAtZ);
        if (outer.cover == BoxCover::Region) {
          CHECK(own.cover == BoxCover::Region);
        }
        if (own.cover == BoxCover::Outside) {
          // Below a RegionOrOutside box: no point of it reaches the region's surface, so the walk
          // that keeps the region culls it by its bound, as it culls an Outside leaf.
          CHECK(region_deepest_bound(tool, outer.region, inner) < -kSurfaceTolerance_mm);
          continue;
        }
        ++inner_settled;
        LONGS_EQUAL(outer.region, own.region);
        DOUBLES_EQUAL(own.deepest_bound_mm, region_deepest_bound(tool, outer.region, inner), 0.0);
        CHECK(own.deepest_bound_mm <= outer.deepest_bound_mm);
      }
    }
    CHECK_TEXT(inner_settled > 1000, sample.name);
  }
}

// The walk under a settled node asks UprightDepthSpan first and region_depth_range only when it
// is unsure: every answer it gives must be the one region_depth_range's numbers give, and it must
// be unsure only where it has to be, for every
// region of every sample tool, with thresholds at the query's (half the tolerance and the
// tolerance) and at a few tenths of a millimetre, where boxes cross them often.
TEST(MeridianBox, TheDepthSpanWithoutASqrtAgreesWithTheDepthRangeAndLeavesOnlyWhatItMust) {
  std::mt19937_64 random(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d tip(20.0, -7.5, 3.25);
  for (const auto& sample : kSampleTools) {
    ToolBsp tool{};
    CHECK(build_tool_bsp(sample.spec, tool).ok);
    for (std::uint8_t region = 0; region < tool.region_count; ++region) {
      const ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
      for (const auto& [shallow, deep] : {std::pair{0.5 * kSurfaceTolerance_mm, kSurfaceTolerance_mm},
                                          std::pair{0.1, 0.3}}) {
        const UprightDepthSpan span(tool, region, tip, shallow, deep);
        LONGS_EQUAL(region, span.region());
        int answered = 0;
        for (int i = 0; i < 3000; ++i) {
          // A box near the surface's reach, 10 um to 1 mm across, around the axis or beside it.
          const double reach = surface.kind == SurfaceKind::PlaneZ ? 1.0 : surface.radius_mm;
          const Eigen::Vector3d corner(reach * (2.0 * unit(random) - 1.2), reach * (2.0 * unit(random) - 1.2),
                                       tool.envelope.total_length_mm * (1.1 * unit(random) - 0.05));
          const double size = std::pow(10.0, -2.0 + 2.0 * unit(random));
          const Eigen::Vector3d low = tip + corner;
          const Eigen::Vector3d high = low + size * Eigen::Vector3d(unit(random), unit(random), unit(random));
          const DepthRange range = region_depth_range(tool, region, upright_meridian_box(tip, low, high));
          switch (span(low, high)) {
            case DepthSpan::Shallower:
              CHECK_TEXT(range.deepest_mm < shallow, sample.name);
              ++answered;
              break;
            case DepthSpan::Between: {
              CHECK_TEXT(range.deepest_mm >= shallow && range.shallowest_mm <= deep, sample.name);
              // The leaf's bound: never below the range's, and off it by no more than 1e-12 of the reach.
              const double bound = span.deepest_bound(low, high);
              CHECK_TEXT(bound >= range.deepest_mm && bound - range.deepest_mm <= 1e-11, sample.name);
              ++answered;
              break;
            }
            case DepthSpan::Unsure:
              // Left to the sqrt: a torus, a side whose solid is outside it, a box wholly deeper
              // than `deep` (the walk wants its numbers), or one within rounding of a threshold.
              CHECK_TEXT(surface.kind == SurfaceKind::Torus || surface.solid_side != SolidSide::Below ||
                             range.shallowest_mm > deep || std::abs(range.deepest_mm - shallow) < 1e-6 ||
                             std::abs(range.shallowest_mm - deep) < 1e-6,
                         sample.name);
              break;
          }
        }
        CHECK_TEXT(surface.kind == SurfaceKind::Torus ? answered == 0 : answered > 100, sample.name);
      }
    }
  }
}

// A point at a given distance from a ball's centre (straight below it) or from a side's axis: its
// depth is the radius less that distance, give or take rounding. Boxes of one point within a few
// units of rounding of a threshold are answered as the sqrt answers them, or not at all; a
// micrometre either side of it, they are answered; a surface whose numbers are not finite is not.
TEST(MeridianBox, TheDepthSpanAnswersAMicrometreFromAThresholdAndLeavesRoundingToTheSqrt) {
  ToolBsp tool{};
  CHECK(build_tool_bsp(kSampleTools[2].spec, tool).ok);  // ball d3: a hemisphere under the flutes' side
  const Eigen::Vector3d tip(20.0, -7.5, 3.25);
  const double shallow = 0.1;
  const double deep = 0.3;
  int kinds = 0;
  for (std::uint8_t region = 0; region < tool.region_count; ++region) {
    const ImplicitSurface& surface = tool.surfaces[tool.regions[region].surface];
    if (surface.kind != SurfaceKind::Sphere && surface.kind != SurfaceKind::Cylinder) {
      continue;
    }
    ++kinds;
    const UprightDepthSpan span(tool, region, tip, shallow, deep);
    const auto at_distance = [&](double distance) -> Eigen::Vector3d {
      return surface.kind == SurfaceKind::Sphere ? tip + Eigen::Vector3d(0.0, 0.0, surface.center_z_mm - distance)
                                                 : tip + Eigen::Vector3d(distance, 0.0, 5.0);
    };
    const auto answer = [&](double distance) {
      const Eigen::Vector3d p = at_distance(distance);
      const DepthRange range = region_depth_range(tool, region, upright_meridian_box(tip, p, p));
      const DepthSpan told = span(p, p);
      if (told == DepthSpan::Shallower) {
        CHECK(range.deepest_mm < shallow);
      } else if (told == DepthSpan::Between) {
        CHECK(range.deepest_mm >= shallow && range.shallowest_mm <= deep);
      }
      return told;
    };
    for (const double threshold : {shallow, deep}) {
      for (int ulps = -4; ulps <= 4; ++ulps) {
        static_cast<void>(answer(surface.radius_mm - threshold + ulps * 4e-16));
      }
    }
    // A micrometre from each threshold: shallow beyond the first, between the two, wholly deep
    // (the walk's sqrt, for its numbers) beyond the second.
    CHECK(answer(surface.radius_mm - shallow + 1e-6) == DepthSpan::Shallower);
    CHECK(answer(surface.radius_mm - shallow - 1e-6) == DepthSpan::Between);
    CHECK(answer(surface.radius_mm - deep + 1e-6) == DepthSpan::Between);
    CHECK(answer(surface.radius_mm - deep - 1e-6) == DepthSpan::Unsure);
    // A radius that is not a number: no answer. A centre at infinity: the sqrt's answer (every
    // point infinitely far, so shallow) or none.
    ToolBsp damaged = tool;
    damaged.surfaces[damaged.regions[region].surface].radius_mm = std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector3d p = at_distance(surface.radius_mm - 0.2);
    CHECK(UprightDepthSpan(damaged, region, tip, shallow, deep)(p, p) == DepthSpan::Unsure);
    damaged = tool;
    damaged.surfaces[damaged.regions[region].surface].center_z_mm = std::numeric_limits<double>::infinity();
    const DepthSpan far_centre = UprightDepthSpan(damaged, region, tip, shallow, deep)(p, p);
    const DepthRange far_range = region_depth_range(damaged, region, upright_meridian_box(tip, p, p));
    CHECK(far_centre != DepthSpan::Shallower || far_range.deepest_mm < shallow);
    CHECK(far_centre != DepthSpan::Between || (far_range.deepest_mm >= shallow && far_range.shallowest_mm <= deep));
  }
  LONGS_EQUAL(3, kinds);  // the ball, the flutes' side and the holder's
}
