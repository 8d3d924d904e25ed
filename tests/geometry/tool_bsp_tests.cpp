// The tool BSP against an independent outline: inside/outside, exact depth, escape direction, continuity.
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "tests/support/sample_tools.hpp"
#include "tests/support/tool_profile_reference.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;
using stencil::test::kSampleTools;
using stencil::test::ToolProfileReference;

namespace {

constexpr int kSamplesPerTool = 20000;

ToolBsp build(const ToolSpec& spec) {
  ToolBsp tool{};
  const ToolBuildResult result = build_tool_bsp(spec, tool);
  CHECK_TRUE(result.ok);
  return tool;
}

// A random point in a box a little larger than the tool, in the tool frame.
Eigen::Vector3d random_point_near(const ToolProfileReference& reference, std::mt19937_64& rng) {
  const double reach = 1.2 * reference.max_radius();
  const double height = reference.total_length();
  std::uniform_real_distribution<double> across(-reach, reach);
  std::uniform_real_distribution<double> along(-0.1 * height, 1.1 * height);
  return {across(rng), across(rng), along(rng)};
}

// A random point inside the tool (rejection sampling against the reference outline).
Eigen::Vector3d random_point_inside(const ToolProfileReference& reference, std::mt19937_64& rng) {
  for (;;) {
    const Eigen::Vector3d point = random_point_near(reference, rng);
    if (reference.contains(point.head<2>().norm(), point.z())) {
      return point;
    }
  }
}

double reference_distance(const ToolProfileReference& reference, const Eigen::Vector3d& point) {
  return reference.distance_to_surface(point.head<2>().norm(), point.z());
}

double depth_at(const ToolBsp& tool, const Eigen::Vector3d& point) {
  return classify_in_tool_frame(tool, point).depth_mm;
}

}  // namespace

TEST_GROUP(ToolBsp){};

TEST(ToolBsp, InsideOrOutsideAgreesWithTheOutlineForEveryToolKind) {
  std::mt19937_64 rng(1);
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    int inside = 0;
    int outside = 0;
    for (int i = 0; i < kSamplesPerTool; ++i) {
      const Eigen::Vector3d point = random_point_near(reference, rng);
      if (reference_distance(reference, point) < 1e-7) {
        continue;  // on the surface: covered by its own test
      }
      const bool expected_inside = reference.contains(point.head<2>().norm(), point.z());
      const PointContact contact = classify_in_tool_frame(tool, point).contact;
      CHECK_TEXT(contact != PointContact::BadTree, sample.name);
      CHECK_EQUAL_TEXT(expected_inside, contact != PointContact::Outside, sample.name);
      (expected_inside ? inside : outside) += 1;
    }
    CHECK_TEXT(inside > kSamplesPerTool / 20 && outside > kSamplesPerTool / 20, sample.name);
  }
}

TEST(ToolBsp, DepthIsTheExactDistanceToTheToolSurface) {
  std::mt19937_64 rng(2);
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    for (int i = 0; i < kSamplesPerTool; ++i) {
      const Eigen::Vector3d point = random_point_inside(reference, rng);
      const PointClassification result = classify_in_tool_frame(tool, point);
      const double expected = reference_distance(reference, point);
      DOUBLES_EQUAL_TEXT(expected, result.depth_mm, 1e-9, sample.name);
      if (expected > 2 * kSurfaceTolerance_mm) {
        CHECK_TEXT(result.contact == PointContact::Penetrating, sample.name);
      } else if (expected < 0.5 * kSurfaceTolerance_mm) {
        CHECK_TEXT(result.contact == PointContact::Touching, sample.name);
      }
    }
  }
}

TEST(ToolBsp, EscapeDirectionLeadsStraightToTheNearestSurfacePoint) {
  std::mt19937_64 rng(3);
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    for (int i = 0; i < kSamplesPerTool; ++i) {
      const Eigen::Vector3d point = random_point_inside(reference, rng);
      const PointClassification result = classify_in_tool_frame(tool, point);
      DOUBLES_EQUAL_TEXT(1.0, result.escape_direction.norm(), 1e-12, sample.name);
      // Moving by the depth along the escape direction lands on the surface.
      const Eigen::Vector3d foot = point + result.depth_mm * result.escape_direction;
      DOUBLES_EQUAL_TEXT(0.0, reference_distance(reference, foot), 1e-9, sample.name);
    }
  }
}

TEST(ToolBsp, EscapeDirectionIsMinusTheGradientOfDepth) {
  std::mt19937_64 rng(4);
  constexpr double step = 1e-6;
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    int differentiable = 0;
    for (int i = 0; i < kSamplesPerTool / 4; ++i) {
      const Eigen::Vector3d point = random_point_inside(reference, rng);
      const PointClassification result = classify_in_tool_frame(tool, point);
      if (result.depth_mm < 10 * step) {
        continue;
      }
      // Depth falls at rate 1 along the escape direction: the fastest a distance can fall.
      const double ahead = depth_at(tool, point + step * result.escape_direction);
      DOUBLES_EQUAL_TEXT(result.depth_mm - step, ahead, 1e-9, sample.name);
      // Where depth is differentiable (a central-difference gradient of length 1), they agree.
      Eigen::Vector3d gradient;
      for (int axis = 0; axis < 3; ++axis) {
        const Eigen::Vector3d offset = step * Eigen::Vector3d::Unit(axis);
        gradient[axis] = (depth_at(tool, point + offset) - depth_at(tool, point - offset)) / (2 * step);
      }
      if (std::abs(gradient.norm() - 1.0) < 1e-6) {
        ++differentiable;
        CHECK_TEXT((gradient + result.escape_direction).norm() < 1e-5, sample.name);
      }
    }
    CHECK_TEXT(differentiable > kSamplesPerTool / 5, sample.name);
  }
}

TEST(ToolBsp, DepthIsContinuousAcrossRegionBoundaries) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    const double hop = 0.01 * reference.max_radius();  // mm: small against the tool, big enough to cross
    int crossings = 0;
    for (int i = 0; i < kSamplesPerTool; ++i) {
      const Eigen::Vector3d point = random_point_inside(reference, rng);
      const Eigen::Vector3d direction = Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
      const Eigen::Vector3d neighbour = point + hop * direction;
      const PointClassification here = classify_in_tool_frame(tool, point);
      const PointClassification there = classify_in_tool_frame(tool, neighbour);
      if (there.contact != PointContact::Penetrating || here.region == there.region) {
        continue;
      }
      ++crossings;
      // A distance field changes no faster than the distance moved.
      CHECK_TEXT(std::abs(here.depth_mm - there.depth_mm) <= hop + 1e-12, sample.name);
    }
    CHECK_TEXT(crossings > 50, sample.name);
  }
}

TEST(ToolBsp, PointsOnTheSurfaceTouchWithZeroDepth) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    for (int i = 0; i < kSamplesPerTool / 4; ++i) {
      const auto on_surface = reference.surface_point(unit(rng), unit(rng));
      const double angle = 2 * std::numbers::pi * unit(rng);
      const Eigen::Vector3d point(on_surface.r * std::cos(angle), on_surface.r * std::sin(angle), on_surface.z);
      const PointClassification result = classify_in_tool_frame(tool, point);
      CHECK_TEXT(result.contact == PointContact::Touching, sample.name);
      CHECK_EQUAL_TEXT(0.0, result.depth_mm, sample.name);
    }
  }
}

TEST(ToolBsp, PenetratesOnlyBeyondTheSurfaceTolerance) {
  const ToolBsp tool = build(kSampleTools[0].spec);  // flat d3: bottom at z = 0
  CHECK(classify_in_tool_frame(tool, {0.1, 0.0, -1e-6}).contact == PointContact::Outside);
  CHECK(classify_in_tool_frame(tool, {0.1, 0.0, -2 * kSurfaceTolerance_mm}).contact == PointContact::Outside);
  CHECK(classify_in_tool_frame(tool, {0.1, 0.0, 2 * kSurfaceTolerance_mm}).contact == PointContact::Penetrating);
  CHECK(classify_in_tool_frame(tool, {0.1, 0.0, 0.5 * kSurfaceTolerance_mm}).contact == PointContact::Touching);
  const PointClassification just_in = classify_in_tool_frame(tool, {0.1, 0.0, 1e-6});
  CHECK(just_in.contact == PointContact::Penetrating);
  DOUBLES_EQUAL(1e-6, just_in.depth_mm, 1e-15);
  CHECK((just_in.escape_direction - Eigen::Vector3d(0, 0, -1)).norm() < 1e-15);
}

TEST(ToolBsp, ReportsTheFaceThatIsNearest) {
  const ToolBsp tool = build(kSampleTools[5].spec);  // bull d6 r1, flutes 8, holder d10 l20
  const auto face_at = [&](const Eigen::Vector3d& point) {
    const PointClassification result = classify_in_tool_frame(tool, point);
    CHECK(result.contact == PointContact::Penetrating);
    return tool.regions[result.region].face;
  };
  CHECK(face_at({0.5, 0.0, 0.1}) == ToolFace::Bottom);
  CHECK(face_at({2.5, 0.0, 0.5}) == ToolFace::Corner);
  CHECK(face_at({2.8, 0.0, 4.0}) == ToolFace::FluteSide);
  CHECK(face_at({4.0, 0.0, 8.1}) == ToolFace::HolderStep);
  CHECK(face_at({2.5, 0.0, 8.2}) == ToolFace::HolderEdge);
  CHECK(face_at({4.9, 0.0, 15.0}) == ToolFace::HolderSide);
  CHECK(face_at({0.0, 0.0, 27.9}) == ToolFace::HolderTop);
}

TEST(ToolBsp, ClassifyingAtAPoseMatchesTheToolFrame) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::uniform_real_distribution<double> position(-50.0, 50.0);
  for (const auto& sample : kSampleTools) {
    const ToolBsp tool = build(sample.spec);
    const ToolProfileReference reference(sample.spec);
    for (int i = 0; i < 2000; ++i) {
      const Eigen::Vector3d axis = Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
      const Eigen::Vector3d tip(position(rng), position(rng), position(rng));
      const Eigen::Matrix3d rotation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix();
      const Eigen::Vector3d local = random_point_near(reference, rng);
      const PointClassification in_tool = classify_in_tool_frame(tool, local);
      const PointClassification in_world = classify_at_pose(tool, tip, axis, tip + rotation * local);
      CHECK_TEXT(in_tool.contact == in_world.contact || reference_distance(reference, local) < 1e-9, sample.name);
      DOUBLES_EQUAL_TEXT(in_tool.depth_mm, in_world.depth_mm, 1e-9, sample.name);
      if (in_tool.contact == PointContact::Penetrating && local.head<2>().norm() > 1e-6) {
        CHECK_TEXT((rotation * in_tool.escape_direction - in_world.escape_direction).norm() < 1e-9, sample.name);
      }
    }
  }
}

TEST(ToolBsp, EscapeIsStillTheFastestWayOutAtTheCentreOfABallOrCornerTube) {
  // Where the gradient is undefined the fallback direction must still lower depth at rate 1.
  const ToolBsp ball = build(kSampleTools[2].spec);  // ball d3: sphere centre at z = 1.5 on the axis
  const ToolBsp bull = build(kSampleTools[5].spec);  // bull d6 r1: corner tube centre at r = 2, z = 1
  constexpr double step = 1e-4;
  for (const auto& [tool, centre] : {std::pair{&ball, Eigen::Vector3d(0.0, 0.0, 1.5)},
                                     std::pair{&bull, Eigen::Vector3d(2.0, 0.0, 1.0)}}) {
    const PointClassification at_centre = classify_in_tool_frame(*tool, centre);
    CHECK(at_centre.contact == PointContact::Penetrating);
    DOUBLES_EQUAL(1.0, at_centre.escape_direction.norm(), 1e-12);
    DOUBLES_EQUAL(at_centre.depth_mm - step, depth_at(*tool, centre + step * at_centre.escape_direction), 1e-9);
  }
}

TEST(ToolBsp, EscapeIsRadialEvenVeryNearTheAxis) {
  const ToolBsp tool = build(kSampleTools[1].spec);  // flat d6 l3, shank d6 l3: the side is nearest at mid-height
  for (const double r : {1e-6, 1e-9}) {
    const PointClassification result = classify_in_tool_frame(tool, {0.0, r, 3.0});
    CHECK(result.contact == PointContact::Penetrating);
    CHECK((result.escape_direction - Eigen::Vector3d(0.0, 1.0, 0.0)).norm() < 1e-12);
  }
}

TEST(ToolBsp, APointThatIsNotANumberIsAFaultNotOutside) {
  const ToolBsp tool = build(kSampleTools[0].spec);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(classify_in_tool_frame(tool, {nan, 0.0, 5.0}).contact == PointContact::BadTree);
  CHECK(classify_in_tool_frame(tool, {0.0, 0.0, nan}).contact == PointContact::BadTree);
  CHECK(classify_in_tool_frame(tool, {std::numeric_limits<double>::infinity(), 0.0, 5.0}).contact ==
        PointContact::BadTree);
  CHECK(classify_at_pose(tool, {0.0, 0.0, 0.0}, {nan, 0.0, 1.0}, {0.5, 0.0, 5.0}).contact == PointContact::BadTree);
}

TEST(ToolBsp, ANumberInTheTreeThatIsNotANumberIsAFault) {
  const ToolBsp good = build(kSampleTools[0].spec);  // flat d3 l12 under d10 l20
  const Eigen::Vector3d deep_inside(0.5, 0.0, 5.0);
  for (std::size_t surface = 0; surface < good.surface_count; ++surface) {
    ToolBsp damaged = good;
    damaged.surfaces[surface].radius_mm = std::numeric_limits<double>::quiet_NaN();
    damaged.surfaces[surface].center_z_mm = std::numeric_limits<double>::quiet_NaN();
    const PointContact contact = classify_in_tool_frame(damaged, deep_inside).contact;
    // Either the damaged surface is on this point's path (a fault), or the answer is unchanged.
    CHECK(contact == PointContact::BadTree || contact == classify_in_tool_frame(good, deep_inside).contact);
  }
  ToolBsp flute_side_nan = good;
  flute_side_nan.surfaces[1].radius_mm = std::numeric_limits<double>::quiet_NaN();  // the flutes' cylinder
  CHECK(classify_in_tool_frame(flute_side_nan, deep_inside).contact == PointContact::BadTree);
}

TEST(ToolBsp, ABrokenTreeIsReportedNotWalkedForever) {
  ToolBsp tool = build(kSampleTools[0].spec);
  ToolBsp looping = tool;
  looping.nodes[1].when_true = {BspLink::Kind::Node, 0};  // a link back to the root
  looping.nodes[1].when_false = {BspLink::Kind::Node, 0};
  looping.nodes[0].when_true = {BspLink::Kind::Node, 1};
  looping.nodes[0].when_false = {BspLink::Kind::Node, 1};
  CHECK(classify_in_tool_frame(looping, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);

  ToolBsp no_nodes = tool;
  no_nodes.node_count = 0;
  CHECK(classify_in_tool_frame(no_nodes, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);

  ToolBsp bad_surface = tool;
  bad_surface.nodes[0].surface_a = 200;
  CHECK(classify_in_tool_frame(bad_surface, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);

  ToolBsp bad_region = tool;
  bad_region.region_count = 0;
  CHECK(classify_in_tool_frame(bad_region, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);

  // Counts beyond the arrays' capacity must not lead to reading past them.
  ToolBsp too_many_surfaces = tool;
  too_many_surfaces.surface_count = 255;
  too_many_surfaces.nodes[0].surface_a = 200;
  CHECK(classify_in_tool_frame(too_many_surfaces, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);
  ToolBsp too_many_nodes = tool;
  too_many_nodes.node_count = kMaxToolNodes + 1;
  CHECK(classify_in_tool_frame(too_many_nodes, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);
  ToolBsp too_many_regions = tool;
  too_many_regions.region_count = kMaxToolRegions + 1;
  CHECK(classify_in_tool_frame(too_many_regions, {0.1, 0.0, 1.0}).contact == PointContact::BadTree);

  // A backward link that reaches a region (not a loop) is refused too, not followed.
  ToolBsp backward = tool;
  const std::size_t last = backward.node_count - 1;
  backward.nodes[last].when_true = {BspLink::Kind::Node, 1};
  backward.nodes[last].when_false = {BspLink::Kind::Node, 1};
  int refused = 0;
  for (double r = 0.25; r < 5.0; r += 0.5) {
    for (double z = 0.5; z < 32.0; z += 0.5) {
      refused += classify_in_tool_frame(backward, {r, 0.0, z}).contact == PointContact::BadTree ? 1 : 0;
    }
  }
  CHECK(refused > 0);
}
