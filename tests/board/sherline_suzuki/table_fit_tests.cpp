// Tables and stock against the rig they are to be cut on (board/sherline_suzuki/table_fit): the part
// inside the configured travel from the work offset and inside the device's reach, the tables' tool
// no longer than it sticks out; each refusal names the axis and both extents. Against the compiled-in
// rig's facts, with headers written here.
#include <array>
#include <string>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sherline_suzuki/table_fit.hpp"
#include "firmware/core/tables/table_format.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sherline_suzuki;

namespace {

// The rig's default job: home at the workspace's far top corner, the touch-off's own tool.
TableFitJob home_job() { return {kHomeWorldMm, 0.0, 0.0}; }

tables::TableHeader header_spanning(std::array<double, 3> low, std::array<double, 3> high, double flutes_mm = 0.0) {
  tables::TableHeader header{};
  for (std::size_t a = 0; a < 3; ++a) {
    header.part_min_mm[a] = low[a];
    header.part_max_mm[a] = high[a];
  }
  header.tool_flute_length_mm = flutes_mm;
  return header;
}

}  // namespace

TEST_GROUP(TableFit){};

TEST(TableFit, TheConfiguredTravelRunsFromTheHomeIntoTheWorkspaceOnEveryAxis) {
  std::array<double, 3> low{}, high{};
  configured_travel(kRig, home_job(), low, high);
  // Every machine axis counts against the world's (machine_sign -1) from the far top corner.
  DOUBLES_EQUAL(0.0, low[0], 1e-12);
  DOUBLES_EQUAL(50.0, high[0], 1e-12);
  DOUBLES_EQUAL(0.0, low[1], 1e-12);
  DOUBLES_EQUAL(25.0, high[1], 1e-12);
  DOUBLES_EQUAL(0.0, low[2], 1e-12);
  DOUBLES_EQUAL(25.0, high[2], 1e-12);
}

TEST(TableFit, AToolStickingOutFurtherLowersOnlyTheZTravel) {
  std::array<double, 3> low{}, high{};
  configured_travel(kRig, {kHomeWorldMm, 12.0, 10.0}, low, high);
  DOUBLES_EQUAL(-2.0, low[2], 1e-12);
  DOUBLES_EQUAL(23.0, high[2], 1e-12);
  DOUBLES_EQUAL(0.0, low[0], 1e-12);
  DOUBLES_EQUAL(50.0, high[0], 1e-12);
}

TEST(TableFit, APartInsideTheTravelAndTheReachFits) {
  std::string error;
  CHECK_TRUE(check_tables_fit(header_spanning({10, 5, 0}, {40, 20, 6}), "hex.stbl", kRig, home_job(), error));
  STRCMP_EQUAL("", error.c_str());
}

TEST(TableFit, APartTouchingTheWorkspacesFacesStillFits) {
  std::string error;
  CHECK_TRUE(check_tables_fit(header_spanning({0, 0, 0}, {50, 25, 25}), "whole.stbl", kRig, home_job(), error));
}

TEST(TableFit, APartBeyondTheTravelIsRefusedNamingTheAxisAndBothExtents) {
  std::string error;
  // A work offset 10 mm lower in y: the travel reaches y -10 to 15.
  TableFitJob job = home_job();
  job.home_world_mm[1] = 15.0;
  CHECK_FALSE(check_tables_fit(header_spanning({10, 5, 0}, {40, 20, 6}), "hex.stbl", kRig, job, error));
  STRCMP_EQUAL("hex.stbl: the part spans y 5 to 20 mm; the configured travel reaches y -10 to 15 mm "
               "(machine.travel_mm from the work offset)",
               error.c_str());
}

TEST(TableFit, APartBeyondTheDevicesReachIsRefusedNamingTheReach) {
  // A larger travel than the device reaches (500 device mm / 10 = 50 mm on x).
  RigFacts facts = kRig;
  facts.workspace_mm = {80.0, 25.0, 25.0};
  const TableFitJob job{{80.0, 25.0, 25.0}, 0.0, 0.0};
  std::string error;
  CHECK_FALSE(check_tables_fit(header_spanning({0, 0, 0}, {60, 20, 6}), "big.stbl", facts, job, error));
  STRCMP_EQUAL("big.stbl: the part spans x 0 to 60 mm; the device reaches x 0 to 50 mm "
               "(haptic.reach_mm / haptic.device_mm_per_machine_mm)",
               error.c_str());
}

TEST(TableFit, FlutesLongerThanTheStickOutAreRefusedOnlyWhenTheStickOutIsGiven) {
  const tables::TableHeader header = header_spanning({10, 5, 0}, {40, 20, 6}, 20.0);
  std::string error;
  CHECK_TRUE(check_tables_fit(header, "hex.stbl", kRig, home_job(), error));  // not given: not checked
  CHECK_TRUE(check_tables_fit(header, "hex.stbl", kRig, {kHomeWorldMm, 20.0, 20.0}, error));
  CHECK_FALSE(check_tables_fit(header, "hex.stbl", kRig, {kHomeWorldMm, 15.0, 15.0}, error));
  STRCMP_CONTAINS("hex.stbl: the tables' tool has 20 mm of flutes below its holder; it sticks out 15 mm", error.c_str());
}

TEST(TableFit, TheStockMustLieInsideTheTravel) {
  std::string error;
  CHECK_TRUE(check_stock_fit({0, 0, 0}, {50, 25, 25}, kRig, home_job(), error));
  CHECK_FALSE(check_stock_fit({0, 0, -1}, {50, 25, 10}, kRig, home_job(), error));
  STRCMP_EQUAL("the stock spans z -1 to 10 mm; the configured travel reaches z 0 to 25 mm "
               "(machine.travel_mm from the work offset)",
               error.c_str());
}
