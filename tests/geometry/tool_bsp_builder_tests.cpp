// The tool builder: well-formed flat trees for every tool, and a clear error for bad parameters.
#include <cmath>
#include <cstring>
#include <limits>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "tests/support/sample_tools.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;
using stencil::test::kSampleTools;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

constexpr ToolSpec kBall{CutterKind::Ball, 3.0, 12.0, 0.0, 10.0, 20.0};
constexpr ToolSpec kBull{CutterKind::BullNose, 6.0, 8.0, 1.0, 10.0, 20.0};

bool link_is_sound(const ToolBsp& tool, std::size_t from, const BspLink& link) {
  switch (link.kind) {
    case BspLink::Kind::Node:
      return link.index > from && link.index < tool.node_count;
    case BspLink::Kind::Region:
      return link.index < tool.region_count;
    case BspLink::Kind::Outside:
      return true;
  }
  return false;
}

// Asserts the builder refused the spec, naming the field and the value, and left no tree behind.
void check_refused(const ToolSpec& spec, const char* field, double value) {
  ToolBsp tool{};
  const ToolBuildResult result = build_tool_bsp(spec, tool);
  CHECK_FALSE(result.ok);
  STRCMP_EQUAL(field, result.field);
  CHECK(result.expected != nullptr && std::strlen(result.expected) > 10);
  if (std::isnan(value)) {
    CHECK(std::isnan(result.value));
  } else {
    DOUBLES_EQUAL(value, result.value, 0.0);
  }
  LONGS_EQUAL(0, tool.node_count);
  CHECK(classify_in_tool_frame(tool, {0.0, 0.0, 1.0}).contact == PointContact::BadTree);
}

}  // namespace

TEST_GROUP(ToolBspBuilder){};

TEST(ToolBspBuilder, BuildsAFlatForwardLinkedTreeForEveryTool) {
  for (const auto& sample : kSampleTools) {
    ToolBsp tool{};
    const ToolBuildResult result = build_tool_bsp(sample.spec, tool);
    CHECK_TEXT(result.ok, sample.name);
    CHECK_TEXT(tool.node_count > 0 && tool.node_count <= kMaxToolNodes, sample.name);
    CHECK_TEXT(tool.surface_count <= kMaxToolSurfaces, sample.name);
    CHECK_TEXT(tool.region_count > 0 && tool.region_count <= kMaxToolRegions, sample.name);
    for (std::size_t i = 0; i < tool.node_count; ++i) {
      const BspNode& node = tool.nodes[i];
      CHECK_TEXT(node.surface_a < tool.surface_count, sample.name);
      CHECK_TEXT(node.test != NodeTest::NearerThan || node.surface_b < tool.surface_count, sample.name);
      CHECK_TEXT(link_is_sound(tool, i, node.when_true), sample.name);
      CHECK_TEXT(link_is_sound(tool, i, node.when_false), sample.name);
    }
    for (std::size_t i = 0; i < tool.region_count; ++i) {
      CHECK_TEXT(tool.regions[i].surface < tool.surface_count, sample.name);
    }
  }
}

TEST(ToolBspBuilder, TheLargestToolFitsTheCapacities) {
  // Bull-nose under a wider holder has the most faces; the capacities' comment quotes these counts.
  ToolBsp tool{};
  CHECK(build_tool_bsp(kBull, tool).ok);
  LONGS_EQUAL(10, tool.surface_count);
  LONGS_EQUAL(16, tool.node_count);
  LONGS_EQUAL(7, tool.region_count);
}

TEST(ToolBspBuilder, RecordsTheSpecAndTheEnvelope) {
  ToolBsp tool{};
  CHECK(build_tool_bsp(kBall, tool).ok);
  CHECK(tool.spec.kind == CutterKind::Ball);
  DOUBLES_EQUAL(1.5, tool.envelope.cutter_radius_mm, 0.0);
  DOUBLES_EQUAL(12.0, tool.envelope.flute_length_mm, 0.0);
  DOUBLES_EQUAL(5.0, tool.envelope.holder_radius_mm, 0.0);
  DOUBLES_EQUAL(32.0, tool.envelope.total_length_mm, 0.0);
}

TEST(ToolBspBuilder, RefusesADiameterThatIsNotPositiveAndFinite) {
  for (const double diameter : {0.0, -3.0, kNaN, kInfinity, 2000.0}) {
    ToolSpec spec = kBall;
    spec.diameter_mm = diameter;
    check_refused(spec, "diameter_mm", diameter);
  }
}

TEST(ToolBspBuilder, RefusesACornerRadiusLargerThanTheCutterRadius) {
  for (const double corner : {3.01, 0.0, -1.0, kNaN}) {
    ToolSpec spec = kBull;
    spec.corner_radius_mm = corner;
    check_refused(spec, "corner_radius_mm", corner);
  }
}

TEST(ToolBspBuilder, IgnoresTheCornerRadiusOfToolsWithoutOne) {
  ToolSpec spec = kBall;
  spec.corner_radius_mm = kNaN;
  ToolBsp tool{};
  CHECK(build_tool_bsp(spec, tool).ok);
}

TEST(ToolBspBuilder, RefusesFlutesShorterThanTheCutterRadius) {
  for (const double flute : {1.49, 0.0, kNaN, -kInfinity}) {
    ToolSpec spec = kBall;
    spec.flute_length_mm = flute;
    check_refused(spec, "flute_length_mm", flute);
  }
}

TEST(ToolBspBuilder, RefusesAHolderNarrowerThanTheCutterOrTooShort) {
  ToolSpec narrow = kBall;
  narrow.holder_diameter_mm = 2.9;
  check_refused(narrow, "holder_diameter_mm", 2.9);
  ToolSpec short_holder = kBall;
  short_holder.holder_length_mm = 1.0;
  check_refused(short_holder, "holder_length_mm", 1.0);
  ToolSpec nan_holder = kBall;
  nan_holder.holder_length_mm = kNaN;
  check_refused(nan_holder, "holder_length_mm", kNaN);
}

TEST(ToolBspBuilder, RefusesAnUnknownCutterKind) {
  ToolSpec spec = kBall;
  spec.kind = static_cast<CutterKind>(7);  // as it could arrive from a damaged table
  check_refused(spec, "kind", 7.0);
}

TEST(ToolBspBuilder, ARefusedBuildOverwritesAPreviousTree) {
  ToolBsp tool{};
  CHECK(build_tool_bsp(kBall, tool).ok);
  ToolSpec bad = kBall;
  bad.diameter_mm = -1.0;
  CHECK_FALSE(build_tool_bsp(bad, tool).ok);
  LONGS_EQUAL(0, tool.node_count);
}
