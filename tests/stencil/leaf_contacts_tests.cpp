// One leaf against the upright tool, lane by lane (stencil/leaf_contacts.hpp), checked point by
// point against the tool tree itself (geometry::classify_meridian and classify_at_pose, in double
// precision): the offsets loaded into the lanes, each way a leaf is settled (inside one region,
// straddling its surface, split at a plane of the tree, mixed), the deepest point, the lanes past
// the leaf's end, a damaged tree, and the force sums. The tool is the default 3 mm ball end mill
// under a 10 mm holder, its tip far from the origin (at a point a float holds exactly: see the
// ignored case below for one it does not).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "firmware/core/geometry/meridian_box.hpp"
#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/stencil/leaf_contacts.hpp"
#include "firmware/core/tables/leaf_moments.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::engine;

namespace {

const Eigen::Vector3d kTip(123.4375, 78.90625, 10.0625);
constexpr geometry::ToolSpec kBall{geometry::CutterKind::Ball, 3.0, 12.0, 0.0, 10.0, 20.0};

// The block's sphere, moments and groups' moments: the moments as the generator writes them (the
// loader checks them), the sphere about the points' box's middle holding every point.
void with_moments(tables::LeafBlock& block) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e30), high = Eigen::Vector3d::Constant(-1e30);
  for (std::uint32_t lane = 0; lane < block.point_count; ++lane) {
    const Eigen::Vector3d p(block.x_mm[lane], block.y_mm[lane], block.z_mm[lane]);
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  double radius = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    block.centre_mm[axis] = static_cast<float>(0.5 * (low[axis] + high[axis]));
  }
  const Eigen::Vector3d centre(block.centre_mm[0], block.centre_mm[1], block.centre_mm[2]);
  for (std::uint32_t lane = 0; lane < block.point_count; ++lane) {
    radius = std::max(radius, (Eigen::Vector3d(block.x_mm[lane], block.y_mm[lane], block.z_mm[lane]) - centre).norm());
  }
  block.radius_mm = static_cast<float>(radius * (1.0 + 1e-6));
  tables::store_moments(tables::leaf_moments(block), block);
}

// A leaf's points in a box around `centre` (offsets from the tip), spread over it by a fixed
// pattern, with normals pointing every which way (unit, never along the axis alone).
struct LeafPoints {
  std::array<tables::PackedPoint, tables::kMaxLeafPoints> points{};
  std::array<tables::PackedPoint, tables::kMaxLeafPoints> normals{};
  tables::PartTables part{};
  mutable tables::LeafBlock block{};
  std::uint32_t count = 0;

  LeafPoints(const Eigen::Vector3d& centre, const Eigen::Vector3d& half, std::uint32_t n, const Eigen::Vector3d& tip = kTip)
      : count(n) {
    for (std::uint32_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(i);
      const Eigen::Vector3d spread(std::sin(1.7 * t), std::cos(2.3 * t), std::sin(0.9 * t + 0.5));
      const Eigen::Vector3d p = tip + centre + half.cwiseProduct(spread);
      points[i] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      const Eigen::Vector3d normal = Eigen::Vector3d(std::cos(t), std::sin(t), 0.5).normalized();
      normals[i] = {static_cast<float>(normal.x()), static_cast<float>(normal.y()), static_cast<float>(normal.z())};
    }
    part.points = points.data();
  }

  // The leaf's block as the table generator packs it, from the points and normals as they are now
  // (lanes past count repeat the last point), with its sphere and moments.
  // The block lives in this object: a loaded leaf reads its normals from it.
  [[nodiscard]] const tables::LeafBlock& packed() const {
    block = tables::LeafBlock{};
    block.first_point = 0;
    block.point_count = count;
    for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
      const std::uint32_t i = std::min(lane, count - 1);
      block.x_mm[lane] = points[i].x_mm;
      block.y_mm[lane] = points[i].y_mm;
      block.z_mm[lane] = points[i].z_mm;
      block.nx[lane] = normals[i].x_mm;
      block.ny[lane] = normals[i].y_mm;
      block.nz[lane] = normals[i].z_mm;
    }
    with_moments(block);
    return block;
  }

  [[nodiscard]] Eigen::Vector3d point(std::uint32_t i) const {
    return {double{points[i].x_mm}, double{points[i].y_mm}, double{points[i].z_mm}};
  }

  // The meridian box holding every point, as the query computes it from the leaf's bounds.
  [[nodiscard]] geometry::MeridianBox box() const {
    Eigen::Vector3d low = point(0), high = point(0);
    for (std::uint32_t i = 1; i < count; ++i) {
      low = low.cwiseMin(point(i));
      high = high.cwiseMax(point(i));
    }
    return geometry::upright_meridian_box(kTip, low, high);
  }
};

// What the query does with a leaf of this cover.
bool settle(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover, LeafContacts& leaf) {
  switch (cover.cover) {
    case geometry::BoxCover::Region:
    case geometry::BoxCover::RegionOrOutside:
      return region_leaf_contacts(tool, cover.region, cover.cover == geometry::BoxCover::RegionOrOutside, leaf);
    case geometry::BoxCover::SplitAtZ:
      return split_leaf_contacts(tool, cover, leaf);
    case geometry::BoxCover::Outside:
    case geometry::BoxCover::Mixed:
      break;
  }
  return mixed_leaf_contacts(tool, leaf);
}

// Every lane against the tool tree, point by point in double precision; returns how many
// penetrate, so a case can insist that its leaf has some of each.
std::uint32_t check_against_the_tree(const geometry::ToolBsp& tool, const LeafPoints& points, const LeafContacts& leaf) {
  std::uint32_t penetrating = 0;
  double deepest = 0.0;
  std::uint32_t deepest_lane = 0;
  for (std::uint32_t lane = 0; lane < points.count; ++lane) {
    const geometry::PointClassification c = geometry::classify_at_pose(tool, kTip, Eigen::Vector3d::UnitZ(), points.point(lane));
    const bool inside = c.contact != geometry::PointContact::Outside;
    const bool deep = c.contact == geometry::PointContact::Penetrating;
    CHECK(c.contact != geometry::PointContact::BadTree);
    CHECK_EQUAL(inside, ((leaf.in_tool >> lane) & 1U) != 0);
    CHECK_EQUAL(deep, ((leaf.penetrating_lanes >> lane) & 1U) != 0);
    DOUBLES_EQUAL(deep ? c.depth_mm : 0.0, double{leaf.depth[lane]}, 1e-5);
    if (inside) {
      const Eigen::Vector3d escape(double{leaf.ex[lane]}, double{leaf.ey[lane]}, double{leaf.ez[lane]});
      CHECK((escape - c.escape_direction).norm() < 1e-5);
    }
    if (deep) {
      ++penetrating;
      if (c.depth_mm > deepest) {
        deepest = c.depth_mm;
        deepest_lane = lane;
      }
    }
  }
  LONGS_EQUAL(penetrating, leaf.penetrating);
  DOUBLES_EQUAL(deepest, leaf.max_depth_mm, 1e-12);  // settled in double precision
  if (penetrating > 0) {
    LONGS_EQUAL(deepest_lane, leaf.deepest_lane);
  }
  for (std::uint32_t lane = points.count; lane < tables::kMaxLeafPoints; ++lane) {
    DOUBLES_EQUAL(0.0, double{leaf.depth[lane]}, 0.0);  // past the end: nothing, whatever it repeats
  }
  return penetrating;
}

// Over-aligned (its lanes): static storage, as the query keeps its own, not the test group's heap.
LeafContacts the_leaf{};

}  // namespace

TEST_GROUP(LeafContacts) {
  geometry::ToolBsp tool{};
  LeafContacts& leaf = the_leaf;
  void setup() override { CHECK(geometry::build_tool_bsp(kBall, tool).ok); }

  void check_leaf(const LeafPoints& points, geometry::BoxCover expected_cover) {
    const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
    CHECK(cover.cover == expected_cover);
    load_leaf(points.part, points.packed(), kTip, leaf);
    CHECK(settle(tool, cover, leaf));
    const std::uint32_t penetrating = check_against_the_tree(tool, points, leaf);
    CHECK(penetrating > 0);
  }
};

namespace {

// Every lane's offset from `tip` to a float rounding of its own size, the lanes past the end
// repeating the last point, and the leaf's magnitude a bound on every lane's |x| + |y| + |z|.
void check_loaded(const LeafPoints& points, const Eigen::Vector3d& tip, const LeafContacts& leaf) {
  LONGS_EQUAL(points.count, leaf.count);
  POINTERS_EQUAL(points.points.data(), leaf.points);
  float largest = 0.0F;
  for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
    const Eigen::Vector3d offset = points.point(std::min(lane, points.count - 1)) - tip;
    DOUBLES_EQUAL(offset.x(), double{leaf.x[lane]}, 1e-7);
    DOUBLES_EQUAL(offset.y(), double{leaf.y[lane]}, 1e-7);
    DOUBLES_EQUAL(offset.z(), double{leaf.z[lane]}, 1e-7);
    DOUBLES_EQUAL(double{points.normals[std::min(lane, points.count - 1)].y_mm}, double{leaf.normals->ny[lane]}, 0.0);
    largest = std::max(largest, std::abs(leaf.x[lane]) + std::abs(leaf.y[lane]) + std::abs(leaf.z[lane]));
  }
  // The bound from the block's sphere: above every lane, by no more than its diameter's worth.
  CHECK(leaf.magnitude_mm >= largest);
  CHECK(double{leaf.magnitude_mm} <= double{largest} + 4.0 * double{leaf.normals->radius_mm});
}

}  // namespace

TEST(LeafContacts, TheLanesHoldEachPointsOffsetFromTheTipAndRepeatTheLastPastTheEnd) {
  const LeafPoints points(Eigen::Vector3d(0.3, -0.2, 0.4), Eigen::Vector3d(0.2, 0.2, 0.2), 5);
  load_leaf(points.part, points.packed(), kTip, leaf);
  check_loaded(points, kTip, leaf);
}

// A tip that is not a float: its rest below a float's precision must reach the offsets. Written
// as `tip - double(float(tip))`, GCC 12.2's SLP vectoriser folded the rest of x and y to 0 (the
// object code had `vsubpd %xmm1,%xmm1,%xmm1`): off by up to half a float ulp of the tip (1.9e-6 mm
// here; 7.6e-6 mm beyond 128 mm), where the comment promises a rounding of the offset's own size.
TEST(LeafContacts, AnOffsetFromATipThatIsNotAFloatIsRightToARoundingOfItsOwnSize) {
  const Eigen::Vector3d tip(123.456789, 78.9012345, 10.0625);
  const LeafPoints points(Eigen::Vector3d(0.3, -0.2, 0.4), Eigen::Vector3d(0.2, 0.2, 0.2), 5, tip);
  load_leaf(points.part, points.packed(), tip, leaf);
  check_loaded(points, tip, leaf);
}

TEST(LeafContacts, ALeafInsideTheBallIsSettledByItsSurfaceAsTheTreeWouldSettleEachPoint) {
  check_leaf(LeafPoints(Eigen::Vector3d(0.2, 0.1, 0.6), Eigen::Vector3d(0.15, 0.15, 0.1), 32),
             geometry::BoxCover::Region);
  LONGS_EQUAL(32, leaf.penetrating);
}

TEST(LeafContacts, ALeafAcrossTheBallsSurfaceHasThePointsOutsideLeftOut) {
  check_leaf(LeafPoints(Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d(0.05, 0.05, 0.02), 20),
             geometry::BoxCover::RegionOrOutside);
  CHECK(leaf.penetrating < 20);  // some are below the tip: outside
}

TEST(LeafContacts, ALeafAcrossThePlaneBetweenBallAndFlutesTakesEachSidesSurface) {
  check_leaf(LeafPoints(Eigen::Vector3d(1.3, 0.0, 1.5), Eigen::Vector3d(0.05, 0.05, 0.1), 24),
             geometry::BoxCover::SplitAtZ);
}

TEST(LeafContacts, ALeafAcrossSeveralOfTheTreesTestsIsSettledPointByPoint) {
  const LeafPoints points(Eigen::Vector3d(0.8, 0.0, 1.2), Eigen::Vector3d(1.0, 1.0, 1.0), 32);
  load_leaf(points.part, points.packed(), kTip, leaf);
  CHECK(mixed_leaf_contacts(tool, leaf));
  const std::uint32_t penetrating = check_against_the_tree(tool, points, leaf);
  CHECK(penetrating > 0);
  CHECK(penetrating < 32);
}

TEST(LeafContacts, TheDeepestOfPointsTheFloatsCannotTellApartIsFoundInDoublePrecision) {
  // Two points inside the ball whose lane depths are the same float but whose depths are not.
  LeafPoints pair(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 2);
  const geometry::BoxClassification cover = geometry::classify_meridian_box(
      tool, geometry::upright_meridian_box(kTip, kTip + Eigen::Vector3d(0.1, 0.0, 0.5), kTip + Eigen::Vector3d(0.4, 0.3, 0.8)));
  CHECK(cover.cover == geometry::BoxCover::Region);
  // Candidates by their lane depth: the first two with one float depth and two double ones.
  std::map<float, std::pair<tables::PackedPoint, double>> seen;
  bool found = false;
  tables::PackedPoint first{}, second{};
  for (int i = 0; i < 20000 && !found; ++i) {
    const double t = static_cast<double>(i);
    const Eigen::Vector3d p = kTip + Eigen::Vector3d(0.25 + 0.15 * std::sin(1.3 * t), 0.15 + 0.15 * std::cos(0.7 * t),
                                                     0.65 + 0.15 * std::sin(2.9 * t));
    pair.points[0] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
    pair.count = 1;
    load_leaf(pair.part, pair.packed(), kTip, leaf);
    CHECK(region_leaf_contacts(tool, cover.region, false, leaf));
    const auto [at, added] = seen.emplace(leaf.depth[0], std::make_pair(pair.points[0], leaf.max_depth_mm));
    if (!added && at->second.second < leaf.max_depth_mm) {
      first = at->second.first;  // the shallower first
      second = pair.points[0];
      found = true;
    }
  }
  CHECK_TEXT(found, "no two points with the same float depth among the candidates");
  pair.points[0] = first;
  pair.points[1] = second;
  pair.count = 2;
  load_leaf(pair.part, pair.packed(), kTip, leaf);
  CHECK(region_leaf_contacts(tool, cover.region, false, leaf));
  DOUBLES_EQUAL(double{leaf.depth[0]}, double{leaf.depth[1]}, 0.0);
  check_against_the_tree(tool, pair, leaf);  // the deepest lane and depth: the double-precision ones
  std::swap(pair.points[0], pair.points[1]);
  pair.count = 2;
  load_leaf(pair.part, pair.packed(), kTip, leaf);
  CHECK(region_leaf_contacts(tool, cover.region, false, leaf));
  check_against_the_tree(tool, pair, leaf);
  // A true tie: the first lane at the deepest depth.
  pair.points[1] = pair.points[0];
  pair.count = 2;
  load_leaf(pair.part, pair.packed(), kTip, leaf);
  CHECK(region_leaf_contacts(tool, cover.region, false, leaf));
  LONGS_EQUAL(0, leaf.deepest_lane);
}

TEST(LeafContacts, ADamagedToolTreeIsAFaultNotANumber) {
  const LeafPoints points(Eigen::Vector3d(0.2, 0.1, 0.6), Eigen::Vector3d(0.15, 0.15, 0.1), 8);
  const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
  CHECK(cover.cover == geometry::BoxCover::Region);
  geometry::ToolBsp damaged = tool;
  damaged.surfaces[damaged.regions[cover.region].surface].radius_mm = std::numeric_limits<double>::quiet_NaN();
  load_leaf(points.part, points.packed(), kTip, leaf);
  CHECK_FALSE(region_leaf_contacts(damaged, cover.region, false, leaf));
  geometry::ToolBsp broken = tool;
  broken.node_count = 0;  // no root: every walk is a bad tree
  load_leaf(points.part, points.packed(), kTip, leaf);
  CHECK_FALSE(mixed_leaf_contacts(broken, leaf));
}

TEST(LeafContacts, TheForceSumsAreEachPenetratingPointsDepthAlongItsNormalLessItsEscape) {
  const LeafPoints points(Eigen::Vector3d(0.8, 0.0, 1.2), Eigen::Vector3d(1.0, 1.0, 1.0), 32);
  load_leaf(points.part, points.packed(), kTip, leaf);
  CHECK(mixed_leaf_contacts(tool, leaf));
  const double k = 10.0;
  const double height = 7.5;
  // The same sum in double precision from the tree's own answers.
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
  for (std::uint32_t i = 0; i < points.count; ++i) {
    const geometry::PointClassification c = geometry::classify_at_pose(tool, kTip, Eigen::Vector3d::UnitZ(), points.point(i));
    if (c.contact != geometry::PointContact::Penetrating) {
      continue;
    }
    const Eigen::Vector3d normal(double{points.normals[i].x_mm}, double{points.normals[i].y_mm},
                                 double{points.normals[i].z_mm});
    const Eigen::Vector3d f = k * c.depth_mm * (normal - c.escape_direction).normalized();
    force += f;
    torque += (points.point(i) - kTip - Eigen::Vector3d(0.0, 0.0, height)).cross(f);
  }
  CHECK(force.norm() > 1.0);
  const LeafForceSums sums = leaf_forces(leaf, k, height);
  CHECK((sums.force - force).norm() < 1e-4 * force.norm());
  CHECK((sums.torque - torque).norm() < 1e-4 * torque.norm() + 1e-6);
}

TEST(LeafContacts, APointWhoseNormalIsItsEscapeDirectionGivesNoForce) {
  LeafPoints points(Eigen::Vector3d(0.0, 0.0, 0.5), Eigen::Vector3d(0.0, 0.0, 0.0), 1);  // on the axis, 1 mm in
  // Straight below the ball's centre the escape is straight down: a normal pointing down cancels it.
  points.normals[0] = {0.0F, 0.0F, -1.0F};
  load_leaf(points.part, points.packed(), kTip, leaf);
  CHECK(mixed_leaf_contacts(tool, leaf));
  LONGS_EQUAL(1, leaf.penetrating);
  const LeafForceSums none = leaf_forces(leaf, 10.0, 7.5);
  CHECK(none.force == Eigen::Vector3d::Zero());
  CHECK(none.torque == Eigen::Vector3d::Zero());
  // Turned up, it pushes the tool up with k times the depth.
  points.normals[0] = {0.0F, 0.0F, 1.0F};
  load_leaf(points.part, points.packed(), kTip, leaf);
  CHECK(mixed_leaf_contacts(tool, leaf));
  const LeafForceSums up = leaf_forces(leaf, 10.0, 7.5);
  DOUBLES_EQUAL(10.0 * leaf.max_depth_mm, up.force.z(), 1e-5);
  DOUBLES_EQUAL(0.0, up.force.head<2>().norm(), 1e-7);
}

namespace {

// The leaf as bind_leaf leaves it for the one-pass kernels: its lanes not loaded (NaN here, so a
// kernel that read them would say so).
LeafContacts without_lanes(const LeafContacts& loaded) {
  LeafContacts bound = loaded;
  bound.x.fill(std::numeric_limits<float>::quiet_NaN());
  bound.y.fill(std::numeric_limits<float>::quiet_NaN());
  bound.z.fill(std::numeric_limits<float>::quiet_NaN());
  return bound;
}

// The one-pass force against the two steps, on the leaf as loaded: region_leaf_force against
// region_leaf_contacts then leaf_forces, or for a leaf split at a plane split_leaf_force against
// split_leaf_contacts then leaf_forces. The same count, deepest lane and depth (when searched) and
// the same bits of force and torque; and region_leaf_deepest's count, lane and depth.
void check_one_pass_is_step_by_step(const geometry::ToolBsp& tool, const geometry::BoxClassification& cover,
                                    const LeafContacts& loaded) {
  const bool split = cover.cover == geometry::BoxCover::SplitAtZ;
  const bool or_outside = cover.cover == geometry::BoxCover::RegionOrOutside;
  LeafContacts step_by_step = loaded;
  CHECK(split ? split_leaf_contacts(tool, cover, step_by_step)
              : region_leaf_contacts(tool, cover.region, or_outside, step_by_step));
  const LeafForceSums sums = leaf_forces(step_by_step, 10.0, 7.5);
  CHECK(step_by_step.penetrating > 0);
  for (const bool find_deepest : {true, false}) {
    LeafContacts leaf = without_lanes(loaded);
    RegionLeafForce one_pass{};
    CHECK(split ? split_leaf_force(tool, cover, find_deepest, 10.0, 7.5, leaf, one_pass)
                : region_leaf_force(tool, cover.region, or_outside, find_deepest, 10.0, 7.5, leaf, one_pass));
    LONGS_EQUAL(step_by_step.penetrating, one_pass.penetrating);
    DOUBLES_EQUAL(find_deepest ? step_by_step.max_depth_mm : 0.0, one_pass.max_depth_mm, 0.0);
    LONGS_EQUAL(find_deepest ? step_by_step.deepest_lane : 0U, one_pass.deepest_lane);
    CHECK(sums.force == one_pass.sums.force);  // the same bits, not merely close
    CHECK(sums.torque == one_pass.sums.torque);
  }
  if (!split) {
    // The search for a deep leaf's deepest point: the same count, lane and depth, and no force.
    LeafContacts leaf = without_lanes(loaded);
    RegionLeafForce deepest{};
    CHECK(region_leaf_deepest(tool, cover.region, -std::numeric_limits<double>::infinity(), leaf, deepest));
    LONGS_EQUAL(step_by_step.penetrating, deepest.penetrating);
    DOUBLES_EQUAL(step_by_step.max_depth_mm, deepest.max_depth_mm, 0.0);
    LONGS_EQUAL(step_by_step.deepest_lane, deepest.deepest_lane);
    CHECK(deepest.sums.force == Eigen::Vector3d::Zero() && deepest.sums.torque == Eigen::Vector3d::Zero());
    // With the deepest depth as the floor, the group holding the deepest lane stays: the same lane
    // and depth, from no more lanes than penetrate.
    leaf = without_lanes(loaded);
    CHECK(region_leaf_deepest(tool, cover.region, step_by_step.max_depth_mm, leaf, deepest));
    CHECK(deepest.penetrating > 0 && deepest.penetrating <= step_by_step.penetrating);
    DOUBLES_EQUAL(step_by_step.max_depth_mm, deepest.max_depth_mm, 0.0);
    LONGS_EQUAL(step_by_step.deepest_lane, deepest.deepest_lane);
    // Above every point, every group is left out (with the lanes; without them, none is).
    leaf = without_lanes(loaded);
    CHECK(region_leaf_deepest(tool, cover.region, std::numeric_limits<double>::infinity(), leaf, deepest));
#if defined(__AVX2__)
    LONGS_EQUAL(0, deepest.penetrating);
#else
    LONGS_EQUAL(step_by_step.penetrating, deepest.penetrating);
#endif
  }
}

}  // namespace

TEST(LeafContacts, TheOnePassForceOfALeafInOneRegionIsTheStepByStepOneBitForBit) {
  // Leaves in the ball, by the flutes' side, under the holder's step, by its concave edge, and
  // across the ball's surface: every kind of surface a region can have.
  const std::array<std::pair<Eigen::Vector3d, Eigen::Vector3d>, 7> leaves{{
      {{0.2, 0.1, 0.6}, {0.15, 0.15, 0.1}},
      {{0.1, 0.0, 0.0}, {0.05, 0.05, 0.02}},
      {{1.2, 0.3, 6.0}, {0.1, 0.1, 0.3}},
      {{3.0, 0.5, 12.2}, {0.1, 0.1, 0.05}},
      {{1.0, 0.2, 12.3}, {0.05, 0.05, 0.05}},
      {{4.8, 0.0, 20.0}, {0.05, 0.05, 0.2}},
      {{0.0, 0.0, 31.9}, {0.2, 0.2, 0.05}},
  }};
  std::uint32_t kinds_seen = 0;
  for (const auto& [centre, half] : leaves) {
    for (const std::uint32_t count : {tables::kMaxLeafPoints, 32U, 13U}) {
      const LeafPoints points(centre, half, count);
      const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
      CHECK_TEXT(cover.cover == geometry::BoxCover::Region || cover.cover == geometry::BoxCover::RegionOrOutside,
                 "each leaf lies in one region, or in it or outside");
      kinds_seen |= 1U << static_cast<unsigned>(tool.surfaces[tool.regions[cover.region].surface].kind);
      load_leaf(points.part, points.packed(), kTip, leaf);
      check_one_pass_is_step_by_step(tool, cover, leaf);
    }
  }
  LONGS_EQUAL(0xF, kinds_seen);  // plane, cylinder, sphere and torus
}

namespace {

// Puts point i of the leaf at place(i), and counts the points within the lanes' band of the tool's
// surface (touching, or less than 3e-6 mm from it) as the tree classifies them.
template <typename Place>
std::uint32_t place_points(const geometry::ToolBsp& tool, LeafPoints& points, Place&& place) {
  std::uint32_t on_the_surface = 0;
  for (std::uint32_t i = 0; i < points.count; ++i) {
    const Eigen::Vector3d p = place(i);
    points.points[i] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
    const geometry::PointClassification c =
        geometry::classify_at_pose(tool, kTip, Eigen::Vector3d::UnitZ(), points.point(i));
    const double depth = c.contact == geometry::PointContact::Outside ? -1.0 : c.depth_mm;
    on_the_surface += std::abs(depth) < 3e-6 || c.contact == geometry::PointContact::Touching ? 1U : 0U;
  }
  return on_the_surface;
}

// A leaf of points placed on the tool's surface (place_points): enough of them within the band,
// its box settled as `expected`, the one pass giving the steps' bits, and the steps each point's
// verdict from the tree.
void check_surface_leaf(const geometry::ToolBsp& tool, const LeafPoints& points, std::uint32_t on_the_surface,
                        geometry::BoxCover expected, LeafContacts& leaf) {
  CHECK_TEXT(on_the_surface > 8, "points within the lanes' band of the surface");
  const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
  CHECK(cover.cover == expected);
  load_leaf(points.part, points.packed(), kTip, leaf);
  check_one_pass_is_step_by_step(tool, cover, leaf);
  LeafContacts settled = leaf;
  CHECK(settle(tool, cover, settled));
  check_against_the_tree(tool, points, settled);
}

}  // namespace

TEST(LeafContacts, TheOnePassForceSettlesLanesOnTheSurfaceInDoublePrecisionAsTheStepsDo) {
  // Points on the ball's surface, to a float's rounding: their float depths are within the band,
  // so each is settled again in double precision, in the one pass as in the steps.
  LeafPoints points(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), tables::kMaxLeafPoints);
  const Eigen::Vector3d centre(0.0, 0.0, 1.5);
  const std::uint32_t on_the_surface = place_points(tool, points, [&](std::uint32_t i) {
    const double t = static_cast<double>(i);
    const double polar = 2.0 + 0.4 * std::sin(1.3 * t);  // below the equator, away from the tip
    const double azimuth = 0.3 * std::cos(0.7 * t);
    return Eigen::Vector3d(kTip + centre + 1.5 * Eigen::Vector3d(std::sin(polar) * std::cos(azimuth),
                                                                 std::sin(polar) * std::sin(azimuth), std::cos(polar)));
  });
  check_surface_leaf(tool, points, on_the_surface, geometry::BoxCover::RegionOrOutside, leaf);
}

TEST(LeafContacts, TheOnePassForceOfALeafSplitAtAPlaneIsTheStepByStepOneBitForBit) {
  // Leaves across the plane between the ball and the flutes: inside both, across both surfaces
  // (some lanes within the band of them), and near the axis; and across the plane of the holder's
  // step, one side of it outside the tool.
  const std::array<std::pair<Eigen::Vector3d, Eigen::Vector3d>, 5> leaves{{
      {{1.3, 0.0, 1.5}, {0.05, 0.05, 0.1}},
      {{1.05, 1.05, 1.5}, {0.08, 0.08, 0.2}},
      {{0.1, 0.2, 1.5}, {0.1, 0.1, 0.3}},
      {{1.6, 0.0, 12.0}, {0.1, 0.1, 0.3}},
      {{3.0, 0.5, 20.0}, {0.1, 0.1, 0.3}},
  }};
  std::uint32_t splits = 0, with_an_outside_side = 0, straddling = 0;
  for (const auto& [centre, half] : leaves) {
    for (const std::uint32_t count : {tables::kMaxLeafPoints, 13U}) {
      const LeafPoints points(centre, half, count);
      const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
      if (cover.cover != geometry::BoxCover::SplitAtZ) {
        continue;
      }
      ++splits;
      with_an_outside_side += cover.below.cover == geometry::BoxCover::Outside ||
                                      cover.above.cover == geometry::BoxCover::Outside ? 1U : 0U;
      straddling += cover.below.cover == geometry::BoxCover::RegionOrOutside ||
                            cover.above.cover == geometry::BoxCover::RegionOrOutside ? 1U : 0U;
      load_leaf(points.part, points.packed(), kTip, leaf);
      check_one_pass_is_step_by_step(tool, cover, leaf);
    }
  }
  LONGS_EQUAL(8, splits);  // all but the leaf at the flutes' end, which lies in one region
  LONGS_EQUAL(2, with_an_outside_side);
  LONGS_EQUAL(2, straddling);
}

TEST(LeafContacts, TheOnePassForceOfASplitLeafSettlesLanesOnEitherSurfaceInDoublePrecisionAsTheStepsDo) {
  // Points on the ball's equator and the flutes' cylinder above it, to a float's rounding, every
  // fourth one deep inside: lanes within the band of each side's surface.
  LeafPoints points(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), tables::kMaxLeafPoints);
  const std::uint32_t on_the_surface = place_points(tool, points, [](std::uint32_t i) {
    const double t = static_cast<double>(i);
    const double r = i % 4 == 0 ? 1.2 : 1.5;
    const double azimuth = 0.3 * std::cos(0.7 * t);
    return Eigen::Vector3d(kTip + Eigen::Vector3d(r * std::cos(azimuth), r * std::sin(azimuth), 1.5 + 0.2 * std::sin(1.3 * t)));
  });
  check_surface_leaf(tool, points, on_the_surface, geometry::BoxCover::SplitAtZ, leaf);
}

TEST(LeafContacts, TheOnePassForceSkipsAGroupThatCannotPenetrateAndGivesTheStepsBits) {
  // Across the bottom of the ball: the first two groups of lanes just inside it, the last two just
  // below the tip, outside, each group's sphere short of the surface: skipped in the one pass.
  LeafPoints points(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), tables::kMaxLeafPoints);
  for (std::uint32_t i = 0; i < points.count; ++i) {
    const double t = static_cast<double>(i % tables::kLeafGroupPoints);
    const bool inside = i / tables::kLeafGroupPoints < 2;
    const Eigen::Vector3d p = kTip + Eigen::Vector3d(0.04 * std::sin(1.7 * t), 0.04 * std::cos(2.3 * t),
                                                     (inside ? 0.03 : -0.08) + 0.01 * std::sin(0.9 * t));
    points.points[i] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
  }
  const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
  CHECK(cover.cover == geometry::BoxCover::RegionOrOutside);
  const tables::LeafBlock& block = points.packed();
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[cover.region].surface];
  for (std::uint32_t group = 0; group < tables::kLeafGroups; ++group) {
    const Eigen::Vector3d centroid(block.group_centroid_mm[0][group], block.group_centroid_mm[1][group],
                                   block.group_centroid_mm[2][group]);
    const Eigen::Vector3d offset = centroid - kTip;
    const double depth = geometry::interior_distance(surface, {std::hypot(offset.x(), offset.y()), offset.z()});
    CHECK_EQUAL(group >= 2, depth + double{block.group_radius_mm[group]} < 0.0);  // the last two cannot penetrate
  }
  load_leaf(points.part, block, kTip, leaf);
  check_one_pass_is_step_by_step(tool, cover, leaf);
}

TEST(LeafContacts, TheOnePassForceSkipsEightLanesNoneOfWhichPenetratesAndGivesTheStepsBits) {
  // Across the bottom of the ball: in every group of 16 lanes, the first eight just inside it and
  // the next eight just below the tip, outside. No group is skipped whole (each holds penetrating
  // lanes); every second eight lanes adds no force, and the one pass leaves their force out.
  LeafPoints points(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), tables::kMaxLeafPoints);
  for (std::uint32_t i = 0; i < points.count; ++i) {
    const double t = static_cast<double>(i);
    const bool inside = (i / 8) % 2 == 0;
    const Eigen::Vector3d p = kTip + Eigen::Vector3d(0.04 * std::sin(1.7 * t), 0.04 * std::cos(2.3 * t),
                                                     (inside ? 0.03 : -0.02) + 0.005 * std::sin(0.9 * t));
    points.points[i] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
  }
  const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
  CHECK(cover.cover == geometry::BoxCover::RegionOrOutside);
  load_leaf(points.part, points.packed(), kTip, leaf);
  LeafContacts steps = leaf;
  CHECK(region_leaf_contacts(tool, cover.region, true, steps));
  const LaneMask inside_lanes = 0x00FF00FF00FF00FFULL;
  CHECK_EQUAL(inside_lanes, steps.penetrating_lanes);  // every first eight, and none of the next
  check_one_pass_is_step_by_step(tool, cover, leaf);
}

TEST(LeafContacts, EveryLaneOfAFullLeafIsSettledAsTheTreeSettlesItsPoint) {
  // The lanes past 32 too: a leaf of kMaxLeafPoints points each way a leaf is settled.
  check_leaf(LeafPoints(Eigen::Vector3d(0.2, 0.1, 0.6), Eigen::Vector3d(0.15, 0.15, 0.1), tables::kMaxLeafPoints),
             geometry::BoxCover::Region);
  LONGS_EQUAL(tables::kMaxLeafPoints, leaf.penetrating);
  check_leaf(LeafPoints(Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d(0.05, 0.05, 0.02), tables::kMaxLeafPoints),
             geometry::BoxCover::RegionOrOutside);
  check_leaf(LeafPoints(Eigen::Vector3d(1.3, 0.0, 1.5), Eigen::Vector3d(0.05, 0.05, 0.1), tables::kMaxLeafPoints),
             geometry::BoxCover::SplitAtZ);
  const LeafPoints mixed(Eigen::Vector3d(0.8, 0.0, 1.2), Eigen::Vector3d(1.0, 1.0, 1.0), tables::kMaxLeafPoints);
  load_leaf(mixed.part, mixed.packed(), kTip, leaf);
  CHECK(mixed_leaf_contacts(tool, leaf));
  const std::uint32_t penetrating = check_against_the_tree(tool, mixed, leaf);
  CHECK(penetrating > 0 && penetrating < tables::kMaxLeafPoints);
}

TEST(LeafContacts, ADamagedRegionSurfaceIsAFaultInTheOnePassForceToo) {
  const LeafPoints points(Eigen::Vector3d(0.2, 0.1, 0.6), Eigen::Vector3d(0.15, 0.15, 0.1), 8);
  const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
  geometry::ToolBsp damaged = tool;
  damaged.surfaces[damaged.regions[cover.region].surface].radius_mm = std::numeric_limits<double>::quiet_NaN();
  load_leaf(points.part, points.packed(), kTip, leaf);
  RegionLeafForce out{};
  CHECK_FALSE(region_leaf_force(damaged, cover.region, false, true, 10.0, 7.5, leaf, out));
  CHECK_FALSE(region_leaf_deepest(damaged, cover.region, -std::numeric_limits<double>::infinity(), leaf, out));
  // A floor leaves out no group whose bound is not finite: the fault is still found.
  CHECK_FALSE(region_leaf_deepest(damaged, cover.region, std::numeric_limits<double>::infinity(), leaf, out));
}

TEST(LeafContacts, ADamagedSurfaceOnEitherSideIsAFaultInTheOnePassSplitForceToo) {
  const LeafPoints points(Eigen::Vector3d(1.3, 0.0, 1.5), Eigen::Vector3d(0.05, 0.05, 0.1), 24);
  const geometry::BoxClassification cover = geometry::classify_meridian_box(tool, points.box());
  CHECK(cover.cover == geometry::BoxCover::SplitAtZ);
  load_leaf(points.part, points.packed(), kTip, leaf);
  for (const geometry::BoxPart& side : {cover.below, cover.above}) {
    geometry::ToolBsp damaged = tool;
    damaged.surfaces[damaged.regions[side.region].surface].radius_mm = std::numeric_limits<double>::quiet_NaN();
    RegionLeafForce out{};
    CHECK_FALSE(split_leaf_force(damaged, cover, true, 10.0, 7.5, leaf, out));
  }
}

namespace {

// A patch of `n` points around `centre` (offsets from kTip) on the plane through it with normal
// `normal` (each point's normal `normal`, or `other` for every second point), spread over a disc of
// radius `radius`, packed with its sphere and moments as the table generator packs them.
struct MomentLeaf {
  std::array<tables::PackedPoint, tables::kMaxLeafPoints> points{};
  tables::LeafBlock block{};

  // With `grouped`, the disc is four discs of half the radius, one to each group of lanes (as the
  // generator orders a leaf's points), each a sunflower of its own.
  MomentLeaf(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius, const Eigen::Vector3d& other,
             bool grouped = false) {
    const Eigen::Vector3d u = normal.unitOrthogonal();
    const Eigen::Vector3d v = normal.cross(u);
    block.point_count = tables::kMaxLeafPoints;
    for (std::uint32_t i = 0; i < tables::kMaxLeafPoints; ++i) {
      const std::uint32_t group = i / tables::kLeafGroupPoints;
      const double t = static_cast<double>(grouped ? i % tables::kLeafGroupPoints : i);
      const double points_in_disc = grouped ? tables::kLeafGroupPoints : tables::kMaxLeafPoints;
      const double disc = grouped ? 0.5 * radius : radius;
      const Eigen::Vector3d middle =
          grouped ? Eigen::Vector3d(0.5 * radius * ((group & 1U) != 0 ? 0.7 : -0.7) * u + 0.5 * radius * ((group & 2U) != 0 ? 0.7 : -0.7) * v)
                  : Eigen::Vector3d::Zero();
      const double s = disc * std::sqrt((t + 0.5) / points_in_disc);  // a sunflower: even cover
      const Eigen::Vector3d p = kTip + centre + middle + s * (std::cos(2.39996 * t) * u + std::sin(2.39996 * t) * v);
      points[i] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      const Eigen::Vector3d n = i % 2 == 0 ? normal : other;
      block.x_mm[i] = points[i].x_mm;
      block.y_mm[i] = points[i].y_mm;
      block.z_mm[i] = points[i].z_mm;
      block.nx[i] = static_cast<float>(n.x());
      block.ny[i] = static_cast<float>(n.y());
      block.nz[i] = static_cast<float>(n.z());
    }
    const Eigen::Vector3d middle = kTip + centre;
    double farthest = 0.0;
    for (std::uint32_t i = 0; i < tables::kMaxLeafPoints; ++i) {
      farthest = std::max(farthest, (point(i) - middle.cast<float>().cast<double>()).norm());
    }
    for (int axis = 0; axis < 3; ++axis) {
      block.centre_mm[axis] = static_cast<float>(middle[axis]);
    }
    block.radius_mm = static_cast<float>(farthest * (1.0 + 1e-6));
    with_moments(block);
  }

  [[nodiscard]] Eigen::Vector3d point(std::uint32_t i) const {
    return {double{points[i].x_mm}, double{points[i].y_mm}, double{points[i].z_mm}};
  }
  [[nodiscard]] Eigen::Vector3d normal(std::uint32_t i) const {
    return {double{block.nx[i]}, double{block.ny[i]}, double{block.nz[i]}};
  }
};

// The leaf's points through the tool tree one by one: the force and torque the lanes would sum,
// and the region every point is in (each must penetrate, in one region).
struct PointSums {
  LeafForceSums sums{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::uint8_t region = 0;
};
PointSums sums_point_by_point(const geometry::ToolBsp& tool, const MomentLeaf& leaf, double k, const Eigen::Vector3d& centre) {
  PointSums out;
  for (std::uint32_t i = 0; i < tables::kMaxLeafPoints; ++i) {
    const auto c = geometry::classify_at_pose(tool, kTip, Eigen::Vector3d::UnitZ(), leaf.point(i));
    CHECK(c.contact == geometry::PointContact::Penetrating);
    CHECK(i == 0 || c.region == out.region);
    out.region = c.region;
    const Eigen::Vector3d f = k * c.depth_mm * (leaf.normal(i) - c.escape_direction).normalized();
    out.sums.force += f;
    out.sums.torque += (leaf.point(i) - centre).cross(f);
  }
  return out;
}

constexpr geometry::ToolSpec kFlat{geometry::CutterKind::Flat, 3.0, 12.0, 0.0, 10.0, 20.0};

}  // namespace

// Under a flat end's bottom, on a slanted face: the depth changes linearly over the leaf and the
// escape direction not at all, so the moments give the points' own force sum, to rounding; the
// torque puts that force at the centroid, where the deeper points pull it towards their side: its
// line of action stays within the leaf.
TEST(LeafContacts, ALeafUnderAFlatBottomHasFromItsMomentsTheForceOfItsPoints) {
  geometry::ToolBsp flat{};
  CHECK(geometry::build_tool_bsp(kFlat, flat).ok);
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const MomentLeaf patch(Eigen::Vector3d(0.3, -0.2, 0.4), normal, 0.5, normal);
  const double k = 10.0;
  const Eigen::Vector3d centre = kTip + Eigen::Vector3d(0.0, 0.0, 10.0);
  const PointSums exact = sums_point_by_point(flat, patch, k, centre);
  const LeafMomentForce moment =
      leaf_moment_force(flat.surfaces[flat.regions[exact.region].surface], patch.block, kTip, centre, k);
  CHECK(moment.settled);
  CHECK(exact.sums.force.norm() > 100.0);
  CHECK((moment.force - exact.sums.force).norm() < 1e-5 * exact.sums.force.norm());
  const double lever_error = (moment.torque - exact.sums.torque).norm() / exact.sums.force.norm();
  CHECK(lever_error < double{patch.block.radius_mm});
  CHECK(lever_error > 1e-4);  // the depth's slope over the leaf moves it: not the sum itself
}

// A leaf across an edge (half its normals one way, half another) is not settled from its moments.
TEST(LeafContacts, ALeafAcrossAnEdgeIsVisitedPointByPointNotSettledFromItsMoments) {
  geometry::ToolBsp flat{};
  CHECK(geometry::build_tool_bsp(kFlat, flat).ok);
  const MomentLeaf patch(Eigen::Vector3d(0.3, -0.2, 0.4), Eigen::Vector3d::UnitZ(), 0.2, Eigen::Vector3d::UnitX());
  const PointSums exact = sums_point_by_point(flat, patch, 10.0, kTip);
  CHECK_FALSE(leaf_moment_force(flat.surfaces[flat.regions[exact.region].surface], patch.block, kTip, kTip, 10.0).settled);
}

// In the ball, whose escape directions turn about its centre: a leaf small against its distance to
// the centre and its depth is settled near its points' sum (the error estimate bounds it); one as
// wide as the ball's radius is not.
TEST(LeafContacts, ALeafSmallAgainstTheBallsCurvatureIsSettledNearItsSumAndAWideOneIsNot) {
  const double k = 10.0;
  const Eigen::Vector3d centre = kTip + Eigen::Vector3d(0.0, 0.0, 10.0);
  const Eigen::Vector3d where(0.4, 0.3, 1.0);  // 0.5 mm from the ball's centre (1.5 up), 1 mm deep
  const Eigen::Vector3d normal = Eigen::Vector3d(-0.3, 0.5, 1.0).normalized();
  const MomentLeaf small(where, normal, 0.08, normal);
  const PointSums exact = sums_point_by_point(tool, small, k, centre);
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[exact.region].surface];
  CHECK(surface.kind == geometry::SurfaceKind::Sphere);
  const LeafMomentForce moment = leaf_moment_force(surface, small.block, kTip, centre, k);
  CHECK(moment.settled);
  CHECK((moment.force - exact.sums.force).norm() < kMomentError * exact.sums.force.norm());
  CHECK((moment.force - exact.sums.force).norm() > 1e-7 * exact.sums.force.norm());  // not the sum itself
  const MomentLeaf wide(where, normal, 0.4, normal);
  static_cast<void>(sums_point_by_point(tool, wide, k, centre));  // still wholly inside, in the ball
  CHECK_FALSE(leaf_moment_force(surface, wide.block, kTip, centre, k).settled);
}

// The same wide leaf with its points in four compact groups (as the generator orders them): too
// wide for its own moments, each group small enough for its own, and their sum near the points'.
TEST(LeafContacts, ALeafTooWideForItsOwnMomentsIsSettledFromItsGroupsNearItsSum) {
  const double k = 10.0;
  const Eigen::Vector3d centre = kTip + Eigen::Vector3d(0.0, 0.0, 10.0);
  const Eigen::Vector3d where(0.4, 0.3, 1.0);
  const Eigen::Vector3d normal = Eigen::Vector3d(-0.3, 0.5, 1.0).normalized();
  const MomentLeaf grouped(where, normal, 0.4, normal, true);
  const PointSums exact = sums_point_by_point(tool, grouped, k, centre);
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[exact.region].surface];
  MomentLeaf whole_only = grouped;  // the same leaf without its groups' moments: refused
  std::fill(std::begin(whole_only.block.group_mean_normal[0]), std::end(whole_only.block.group_mean_normal[0]), 0.0F);
  std::fill(std::begin(whole_only.block.group_mean_normal[1]), std::end(whole_only.block.group_mean_normal[1]), 0.0F);
  std::fill(std::begin(whole_only.block.group_mean_normal[2]), std::end(whole_only.block.group_mean_normal[2]), 0.0F);
  CHECK_FALSE(leaf_moment_force(surface, whole_only.block, kTip, centre, k).settled);
  const LeafMomentForce moment = leaf_moment_force(surface, grouped.block, kTip, centre, k);
  CHECK(moment.settled);
  CHECK((moment.force - exact.sums.force).norm() < kMomentError * exact.sums.force.norm());
  CHECK((moment.force - exact.sums.force).norm() > 1e-7 * exact.sums.force.norm());
  // Each group's force at its own centroid: the torque per newton within the leaf's radius.
  CHECK((moment.torque - exact.sums.torque).norm() < double{grouped.block.radius_mm} * exact.sums.force.norm());
  // One group across an edge (its normals two ways): the leaf is visited, not settled.
  MomentLeaf edge = grouped;
  for (std::size_t axis = 0; axis < 3; ++axis) {  // the mean of its normals and +x's
    edge.block.group_mean_normal[axis][2] = 0.5F * (edge.block.group_mean_normal[axis][2] + (axis == 0 ? 1.0F : 0.0F));
  }
  CHECK_FALSE(leaf_moment_force(surface, edge.block, kTip, centre, k).settled);
}

// Where the part's normal is nearly the tool's escape direction, normalize(normal - escape) turns
// with every small change of either: even a small leaf is left to its points.
TEST(LeafContacts, ALeafWhoseNormalIsNearlyItsEscapeDirectionIsNotSettledFromItsMoments) {
  const double k = 10.0;
  const Eigen::Vector3d centre = kTip + Eigen::Vector3d(0.0, 0.0, 10.0);
  const Eigen::Vector3d where(0.4, 0.3, 1.0);
  const Eigen::Vector3d escape = (where - Eigen::Vector3d(0.0, 0.0, 1.5)).normalized();  // from the ball's centre
  const Eigen::Vector3d normal = (escape + Eigen::Vector3d(0.0, 0.05, 0.0)).normalized();
  const MomentLeaf small(where, normal, 0.08, normal);
  const PointSums exact = sums_point_by_point(tool, small, k, centre);
  const geometry::ImplicitSurface& surface = tool.surfaces[tool.regions[exact.region].surface];
  CHECK_FALSE(leaf_moment_force(surface, small.block, kTip, centre, k).settled);
  const MomentLeaf facing(where, -escape, 0.08, -escape);  // the same leaf facing the tool: settled
  static_cast<void>(sums_point_by_point(tool, facing, k, centre));
  CHECK(leaf_moment_force(surface, facing.block, kTip, centre, k).settled);
}
