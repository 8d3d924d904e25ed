// stencil-same-behaviour's comparison of two reports (toolchain/same_behaviour/report_comparison):
// the same apart from the wall clock and their provenance, every other change found and placed by
// its dotted path, what only the newer report has listed as added (allowed), and the default
// journal's start time left out of any string.
#include <string>

#include <nlohmann/json.hpp>

#include "toolchain/same_behaviour/report_comparison.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

TEST_GROUP(ReportComparison){};

TEST(ReportComparison, ReportsLeaveOutTheWallClockAndTheProvenanceButNothingElse) {
  const nlohmann::json older = {{"cycles", 100}, {"wall_s", 3.5},
                                {"provenance", {{"version", "abc"}, {"command_line", {"/old/stencil-sim"}}}}};
  nlohmann::json newer = {{"cycles", 100}, {"wall_s", 4.0},
                          {"provenance", {{"version", "def"}, {"command_line", {"/new/stencil-sim", "--fast"}}}}};
  same_behaviour::ReportComparison result = same_behaviour::compare_reports(older, newer);
  CHECK_EQUAL(0U, result.changed.size());
  CHECK_EQUAL(0U, result.added.size());
  newer["cycles"] = 101;
  result = same_behaviour::compare_reports(older, newer);
  CHECK_EQUAL(1U, result.changed.size());
  STRCMP_CONTAINS("cycles", result.changed[0].c_str());
}

TEST(ReportComparison, WallClockFieldsAreTheMeasuredOnesAtAnyName) {
  CHECK_TRUE(same_behaviour::is_wall_clock_field("wall_s"));
  CHECK_TRUE(same_behaviour::is_wall_clock_field("compute_us"));
  CHECK_TRUE(same_behaviour::is_wall_clock_field("memory_kb"));
  CHECK_TRUE(same_behaviour::is_wall_clock_field("provenance"));
  CHECK_TRUE(same_behaviour::is_wall_clock_field("wakeup_latency_us"));
  CHECK_FALSE(same_behaviour::is_wall_clock_field("cycles"));
  CHECK_FALSE(same_behaviour::is_wall_clock_field("max_force_n"));
}

TEST(ReportComparison, NestedChangesAreNamedByTheirDottedPathAndIndex) {
  const nlohmann::json older = {{"machine", {{"stop_confirmed", true}}},
                                {"job", {{"run_endings", {{{"ending", "complete"}}, {{"ending", "stopped"}}}}}}};
  const nlohmann::json newer = {{"machine", {{"stop_confirmed", false}}},
                                {"job", {{"run_endings", {{{"ending", "complete"}}, {{"ending", "safe state"}}}}}}};
  const same_behaviour::ReportComparison result = same_behaviour::compare_reports(older, newer);
  CHECK_EQUAL(2U, result.changed.size());
  // nlohmann orders an object's keys: job before machine.
  STRCMP_EQUAL("job.run_endings[1].ending: \"stopped\" -> \"safe state\"", result.changed[0].c_str());
  STRCMP_EQUAL("machine.stop_confirmed: true -> false", result.changed[1].c_str());
}

TEST(ReportComparison, ARemovedFieldFailsAndANewOneIsOnlyListed) {
  const nlohmann::json older = {{"cycles", 1}, {"gone", 2}};
  const nlohmann::json newer = {{"cycles", 1}, {"fresh", 3}};
  const same_behaviour::ReportComparison result = same_behaviour::compare_reports(older, newer);
  CHECK_EQUAL(1U, result.changed.size());
  STRCMP_EQUAL("gone: removed (was 2)", result.changed[0].c_str());
  CHECK_EQUAL(1U, result.added.size());
  STRCMP_EQUAL("fresh = 3", result.added[0].c_str());
}

TEST(ReportComparison, ArraysOfAnotherLengthAreOneChangeNotOnePerElement) {
  const nlohmann::json older = {{"runs", {1, 2, 3}}};
  const nlohmann::json newer = {{"runs", {1, 2}}};
  const same_behaviour::ReportComparison result = same_behaviour::compare_reports(older, newer);
  CHECK_EQUAL(1U, result.changed.size());
  STRCMP_CONTAINS("runs: 3 elements -> 2", result.changed[0].c_str());
}

TEST(ReportComparison, NumbersCompareExactly) {
  const nlohmann::json older = {{"max_force_n", 1.0}};
  const nlohmann::json newer = {{"max_force_n", 1.0000000000000002}};
  CHECK_EQUAL(1U, same_behaviour::compare_reports(older, newer).changed.size());
}

TEST(ReportComparison, TheDefaultJournalsStartTimeIsLeftOutOfAnyString) {
  STRCMP_EQUAL("/jobs/stencil-sim-YYYYMMDD-HHMMSS.journal and more",
               same_behaviour::without_start_time("/jobs/stencil-sim-20260101-120000.journal and more").c_str());
  // Not a time stamp: kept as it is.
  STRCMP_EQUAL("stencil-sim-2026-x.journal", same_behaviour::without_start_time("stencil-sim-2026-x.journal").c_str());
  const nlohmann::json older = {{"journal", "a/stencil-sim-20260101-120000.journal"}};
  const nlohmann::json newer = {{"journal", "a/stencil-sim-20261231-235959.journal"}};
  CHECK_EQUAL(0U, same_behaviour::compare_reports(older, newer).changed.size());
  const nlohmann::json elsewhere = {{"journal", "b/stencil-sim-20261231-235959.journal"}};
  CHECK_EQUAL(1U, same_behaviour::compare_reports(older, elsewhere).changed.size());
}
