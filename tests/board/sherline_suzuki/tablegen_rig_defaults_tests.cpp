// The table generator's defaults on this rig (board/sherline_suzuki/tablegen_rig_defaults.cpp): the
// rig's workspace and its largest backlash, so that stencil-tablegen's --workspace and its backlash
// warning follow rig_facts.hpp and nothing else.
#include "board/sherline_suzuki/rig_facts.hpp"
#include "toolchain/tablegen/rig_defaults.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

TEST_GROUP(TablegenRigDefaults){};

TEST(TablegenRigDefaults, AreTheRigsWorkspaceAndLargestBacklash) {
  const tablegen::RigDefaults defaults = tablegen::rig_defaults();
  DOUBLES_EQUAL(50.0, defaults.workspace_mm[0], 0.0);
  DOUBLES_EQUAL(25.0, defaults.workspace_mm[1], 0.0);
  DOUBLES_EQUAL(25.0, defaults.workspace_mm[2], 0.0);
  // x and z: 0.125 mm; y only 0.05.
  DOUBLES_EQUAL(0.125, defaults.largest_backlash_mm, 0.0);
  DOUBLES_EQUAL(board::sherline_suzuki::largest_backlash_mm(), defaults.largest_backlash_mm, 0.0);
}
