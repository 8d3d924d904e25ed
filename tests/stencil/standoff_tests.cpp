// The standoff (issue 20): the grown tool contains the real tool moved anywhere within the standoff
// (what the planner's argument rests on), a virtual tool pressed into a concave corner keeps the
// standoff clear of both faces and of the floor, and a standoff out of range is refused.
#include <cmath>
#include <limits>
#include <random>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/stencil/standoff.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/loaded_part.hpp"
#include "tests/support/sample_tables.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::engine;

namespace {

bool inside(const geometry::ToolBsp& tool, const Eigen::Vector3d& tip, const Eigen::Vector3d& point) {
  return geometry::classify_at_pose(tool, tip, Eigen::Vector3d::UnitZ(), point).contact ==
         geometry::PointContact::Penetrating;
}

// Every kind of tool, the holder wider than the cutter: points inside the real tool with its tip
// moved by up to the standoff (in any direction) are inside the grown tool with its tip the
// standoff below the unmoved one. Points near the holder's step and the cutter's rim first of all.
void check_contains_moved_tool(const geometry::ToolSpec& spec, double standoff) {
  geometry::ToolBsp real{};
  geometry::ToolBsp grown{};
  CHECK(geometry::build_tool_bsp(spec, real).ok);
  CHECK(grow_tool_for_standoff(spec, standoff, grown));
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double reach = spec.holder_diameter_mm;
  const double height = spec.flute_length_mm + spec.holder_length_mm;
  int checked = 0;
  for (int i = 0; i < 200000; ++i) {
    Eigen::Vector3d move(unit(random), unit(random), unit(random));
    if (move.norm() > 1.0 || move.norm() == 0.0) {
      continue;
    }
    move *= standoff;
    // Points in a band around the real tool's surface, where containment could fail.
    const Eigen::Vector3d point(reach * unit(random), reach * unit(random), (height + 1.0) * (0.5 + 0.5 * unit(random)) - 0.5);
    if (!inside(real, move, point)) {
      continue;
    }
    ++checked;
    CHECK(inside(grown, Eigen::Vector3d(0.0, 0.0, -standoff), point));
  }
  CHECK(checked > 10000);
}

struct Loaded : test::LoadedPart {
  explicit Loaded(const std::vector<tablegen::Facet>& facets) : test::LoadedPart(facets) { CHECK(loaded); }
};

}  // namespace

TEST_GROUP(Standoff){};

TEST(Standoff, TheGrownToolContainsTheRealToolMovedAnywhereWithinTheStandoff) {
  // A large standoff, so a wrong growth shows at this sampling; the rig's is 0.015 mm.
  check_contains_moved_tool({geometry::CutterKind::Ball, 3.0, 8.0, 0.0, 6.0, 20.0}, 0.2);
  check_contains_moved_tool({geometry::CutterKind::Flat, 3.0, 8.0, 0.0, 6.0, 20.0}, 0.2);
  check_contains_moved_tool({geometry::CutterKind::BullNose, 4.0, 8.0, 0.5, 6.0, 20.0}, 0.2);
}

TEST(Standoff, AVirtualToolPressedIntoAConcaveCornerKeepsTheStandoffFromBothFacesAndTheFloor) {
  // The slot's floor (z = 3) meets its wall (y = 9.5); the hand presses into both, then onto the
  // stock's floor beside the block.
  const Loaded loaded(tablegen::slotted_block(30.0, 12.0, 6.0, 6.0, 3.0, 10.0, 6.5));
  const double standoff = 0.015;
  StandoffPart view{};
  CHECK(build_standoff_part(loaded.part, standoff, view));
  VirtualTool tool(view, {25.0, 12.5, 3.5});
  // Down into the floor, then along it into the wall, pressed 0.1 mm into both.
  for (const Eigen::Vector3d& hand : {Eigen::Vector3d(25.0, 12.5, 2.9), Eigen::Vector3d(25.0, 10.5, 2.9)}) {
    for (int i = 0; i < 3000; ++i) {
      CHECK(tool.step(hand, ContactParameters{}).status != RemediationStatus::Fault);
    }
  }
  // Against both faces, the standoff off each: the ball's radius plus it from the wall, the tip
  // that far over the floor (within the slip's 1 um clearance and the cloud's spacing).
  DOUBLES_EQUAL(11.0 + standoff, tool.tip_mm().y(), 0.003);
  DOUBLES_EQUAL(3.0 + standoff, tool.tip_mm().z(), 0.003);
  // The real tool is legal there, and a tool grown by a little less than the standoff still is.
  CHECK(check_legal(loaded.part, tool.pose()) == Legality::Legal);
  StandoffPart almost{};
  CHECK(build_standoff_part(loaded.part, 0.9 * standoff, almost));
  CHECK(check_legal(almost.part, {almost.to_engine(tool.tip_mm()), Eigen::Vector3d::UnitZ()}) == Legality::Legal);
  // Down onto the stock's floor: the tip stays the standoff over z = 0.
  VirtualTool floor_tool(view, {45.0, 22.0, 1.0});
  for (int i = 0; i < 3000; ++i) {
    static_cast<void>(floor_tool.step({45.0, 22.0, -1.0}, ContactParameters{}));
  }
  DOUBLES_EQUAL(standoff, floor_tool.tip_mm().z(), 1e-9);
}

TEST(Standoff, AStandoffOutOfRangeIsRefusedAndZeroIsThePartAsItIs) {
  const Loaded loaded(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  StandoffPart view{};
  CHECK_FALSE(build_standoff_part(loaded.part, -0.001, view));
  CHECK_FALSE(build_standoff_part(loaded.part, std::numeric_limits<double>::quiet_NaN(), view));
  CHECK_FALSE(build_standoff_part(loaded.part, kMaxStandoff_mm + 0.001, view));
  CHECK(build_standoff_part(loaded.part, 0.0, view));
  DOUBLES_EQUAL(loaded.part.tool.envelope.cutter_radius_mm, view.part.tool.envelope.cutter_radius_mm, 0.0);
  DOUBLES_EQUAL(loaded.part.header.workspace_mm[2], view.part.header.workspace_mm[2], 0.0);
  CHECK(build_standoff_part(loaded.part, 0.015, view));
  DOUBLES_EQUAL(loaded.part.tool.envelope.cutter_radius_mm + 0.015, view.part.tool.envelope.cutter_radius_mm, 1e-12);
  DOUBLES_EQUAL(loaded.part.header.workspace_mm[2] - 0.015, view.part.header.workspace_mm[2], 1e-12);
}
