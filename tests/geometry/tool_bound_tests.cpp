// The tool's 14-DOP at a pose: holds the whole tool, and is as tight as the envelope allows.
#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "firmware/core/geometry/tool_bound.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "tests/support/sample_tools.hpp"
#include "tests/support/tool_profile_reference.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;
using stencil::test::kSampleTools;
using stencil::test::ToolProfileReference;

namespace {

struct Pose {
  Eigen::Vector3d tip;
  Eigen::Vector3d axis;
  Eigen::Matrix3d rotation;  // tool frame to world
};

Pose random_pose(std::mt19937_64& rng) {
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::uniform_real_distribution<double> position(-50.0, 50.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
  return {{position(rng), position(rng), position(rng)},
          axis,
          Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix()};
}

ToolEnvelope envelope_of(const ToolSpec& spec) {
  ToolBsp tool{};
  CHECK(build_tool_bsp(spec, tool).ok);
  return tool.envelope;
}

}  // namespace

TEST_GROUP(ToolBound){};

TEST(ToolBound, HoldsEveryPointOfTheToolAtRandomPoses) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& sample : kSampleTools) {
    const ToolEnvelope envelope = envelope_of(sample.spec);
    const ToolProfileReference reference(sample.spec);
    for (int trial = 0; trial < 200; ++trial) {
      const Pose pose = random_pose(rng);
      const Kdop14 volume = tool_kdop(envelope, pose.tip, pose.axis);
      for (int i = 0; i < 200; ++i) {
        // Surface points (the outermost there are) and interior points.
        auto point = reference.surface_point(unit(rng), unit(rng));
        if (i % 2 == 1) {
          point.r *= unit(rng);
        }
        const double angle = 2 * std::numbers::pi * unit(rng);
        const Eigen::Vector3d local(point.r * std::cos(angle), point.r * std::sin(angle), point.z);
        CHECK_TEXT(volume.contains(pose.tip + pose.rotation * local), sample.name);
      }
    }
  }
}

TEST(ToolBound, IsTheEnvelopeBoxForAnUprightTool) {
  const ToolEnvelope envelope = envelope_of(kSampleTools[0].spec);  // flat d3 l12 under d10 l20
  const Kdop14 volume = tool_kdop(envelope, {1.0, 2.0, 3.0}, Eigen::Vector3d::UnitZ());
  const double margin = kToolBoundMargin_mm;
  DOUBLES_EQUAL(1.0 - 5.0 - margin, volume.min[0], 1e-12);
  DOUBLES_EQUAL(1.0 + 5.0 + margin, volume.max[0], 1e-12);
  DOUBLES_EQUAL(2.0 - 5.0 - margin, volume.min[1], 1e-12);
  DOUBLES_EQUAL(2.0 + 5.0 + margin, volume.max[1], 1e-12);
  DOUBLES_EQUAL(3.0 - margin, volume.min[2], 1e-12);
  DOUBLES_EQUAL(3.0 + 32.0 + margin, volume.max[2], 1e-12);
  // Along (1,1,1): the tip's rim reaches 1 + 2 + 3 - 1.5 * sqrt(2) at the lowest.
  DOUBLES_EQUAL(6.0 - 1.5 * std::sqrt(2.0) - margin * std::sqrt(3.0), volume.min[3], 1e-12);
}

TEST(ToolBound, HoldsEveryPointTheToolCallsTouching) {
  // Just outside the bottom face and the rim: the BSP may call these touching, so the bound must hold them.
  ToolBsp tool{};
  CHECK(build_tool_bsp(kSampleTools[1].spec, tool).ok);  // flat d6, shank of its own diameter
  const Eigen::Vector3d tip(1.0, 2.0, 3.0);
  const Kdop14 volume = tool_kdop(tool.envelope, tip, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d near_points[] = {{0.5, 0.0, -0.9e-9}, {3.0 + 0.7e-9, 0.0, -0.7e-9}, {0.0, 3.0 + 0.9e-9, 1.0}};
  for (const Eigen::Vector3d& local : near_points) {
    CHECK(classify_in_tool_frame(tool, local).contact == PointContact::Touching);
    CHECK(volume.contains(tip + local));
  }
}

TEST(ToolBound, EachBoundIsReachedByTheEnvelope) {
  // Tight: for every slab, some point on the envelope's rims lies on the bound (to sampling accuracy).
  std::mt19937_64 rng(22);
  const ToolEnvelope envelope = envelope_of(kSampleTools[5].spec);
  for (int trial = 0; trial < 100; ++trial) {
    const Pose pose = random_pose(rng);
    const Kdop14 volume = tool_kdop(envelope, pose.tip, pose.axis);
    Kdop14 rims = Kdop14::empty();
    const double rim_heights[] = {0.0, envelope.flute_length_mm, envelope.flute_length_mm, envelope.total_length_mm};
    const double rim_radii[] = {envelope.cutter_radius_mm, envelope.cutter_radius_mm, envelope.holder_radius_mm,
                                envelope.holder_radius_mm};
    for (int rim = 0; rim < 4; ++rim) {
      for (int step = 0; step < 3600; ++step) {
        const double angle = 2 * std::numbers::pi * step / 3600.0;
        const Eigen::Vector3d local(rim_radii[rim] * std::cos(angle), rim_radii[rim] * std::sin(angle), rim_heights[rim]);
        rims.add(pose.tip + pose.rotation * local);
      }
    }
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      DOUBLES_EQUAL(volume.min[slab], rims.min[slab] - kToolBoundMargin_mm * (slab < 3 ? 1.0 : std::sqrt(3.0)), 1e-5);
      DOUBLES_EQUAL(volume.max[slab], rims.max[slab] + kToolBoundMargin_mm * (slab < 3 ? 1.0 : std::sqrt(3.0)), 1e-5);
    }
  }
}

TEST(ToolBound, TheUprightShortcutGivesTheBoundOfTheGeneralFormula) {
  // The upright axis takes precomputed reaches; an axis a hair off upright takes the square roots.
  // Their bounds may differ by the tilt only, never more.
  for (const auto& sample : stencil::test::kSampleTools) {
    ToolBsp tool{};
    CHECK(build_tool_bsp(sample.spec, tool).ok);
    const Eigen::Vector3d tip(12.0, 7.5, 3.25);
    const Kdop14 upright = tool_kdop(tool.envelope, tip, Eigen::Vector3d::UnitZ());
    const Eigen::Vector3d tilted = Eigen::Vector3d(1e-12, 0.0, 1.0).normalized();
    const Kdop14 general = tool_kdop(tool.envelope, tip, tilted);
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      DOUBLES_EQUAL(general.min[slab], upright.min[slab], 1e-9);
      DOUBLES_EQUAL(general.max[slab], upright.max[slab], 1e-9);
    }
  }
}
