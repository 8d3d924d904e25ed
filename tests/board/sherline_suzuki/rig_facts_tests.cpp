// What follows from the rig's facts (board/sherline_suzuki/rig_facts.hpp) for any rig a configuration
// describes, not only the compiled-in one its static_asserts pin: rounding to steps, the travel past
// the workspace, the largest backlash, the planner's and the CY545's figures, the device's range.
#include "board/sherline_suzuki/rig_facts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sherline_suzuki;

TEST_GROUP(RigFacts){};

TEST(RigFacts, MillimetresRoundToTheNearestStepOnBothSidesOfZero) {
  RigFacts facts = kRig;
  facts.steps_per_mm = 10.0;
  CHECK_EQUAL(3, mm_to_steps(0.26, facts));
  CHECK_EQUAL(2, mm_to_steps(0.24, facts));
  CHECK_EQUAL(-3, mm_to_steps(-0.26, facts));
  CHECK_EQUAL(-2, mm_to_steps(-0.24, facts));
}

TEST(RigFacts, TheLargestBacklashIsTheLargestOfAnyAxis) {
  RigFacts facts = kRig;
  facts.backlash_mm = {0.01, 0.3, 0.2};
  DOUBLES_EQUAL(0.3, largest_backlash_mm(facts), 0.0);
  DOUBLES_EQUAL(0.125, largest_backlash_mm(), 0.0);
}

TEST(RigFacts, TheTravelRunsFromBelowTheSwitchToPastTheWorkspace) {
  DOUBLES_EQUAL(-3.0, travel_min_mm(0), 0.0);
  DOUBLES_EQUAL(55.0, travel_max_mm(0), 0.0);
  DOUBLES_EQUAL(30.0, travel_max_mm(1), 0.0);
  RigFacts facts = kRig;
  facts.home_switch_edge_mm = 1.0;
  DOUBLES_EQUAL(-2.0, travel_min_mm(2, facts), 0.0);
}

TEST(RigFacts, ThePlannerGetsTheMillsSpeedOneUpdateAndTheBacklashInSteps) {
  const motion::PlannerLimits limits = planner_limits(kRig);
  DOUBLES_EQUAL(1.0 / 30.0, limits.update_period_s, 1e-15);
  CHECK_EQUAL(80, limits.backlash_steps[0]);
  CHECK_EQUAL(32, limits.backlash_steps[1]);
  CHECK_EQUAL(80, limits.backlash_steps[2]);
}

TEST(RigFacts, TheCy545GetsItsHomingInStepsOfTheConfiguredRig) {
  RigFacts facts = kRig;
  facts.steps_per_mm = 100.0;
  facts.homing_speed_mm_per_s = 2.0;
  const hal::cy545::Cy545Motion motion = cy545_motion(facts);
  CHECK_EQUAL(200U, motion.homing_rate);
  CHECK_EQUAL(10, motion.homing_chunk_steps);  // 0.1 mm
  CHECK_EQUAL(6400, motion.homing_travel_steps);
  CHECK_EQUAL(2, static_cast<int>(motion.homing_order[0]));  // Z first
}

TEST(RigFacts, TheProgramsDeviceRangeIsTheReachPlusItsMarginAroundTheReachsCentre) {
  const hal::HapticRange range = programs_device_range(kRig);
  DOUBLES_EQUAL(275.0, range.position_limit_mm[0], 0.0);  // 500 / 2 + 25
  DOUBLES_EQUAL(150.0, range.position_limit_mm[1], 0.0);
  DOUBLES_EQUAL(250.0, range.position_centre_mm[0], 0.0);
  DOUBLES_EQUAL(125.0, range.position_centre_mm[2], 0.0);
  DOUBLES_EQUAL(0.0, kCentredDeviceRange.position_centre_mm[1], 0.0);
}

TEST(RigFacts, PeriodsFollowTheRates) {
  RigFacts facts = kRig;
  facts.haptic_rate_hz = 500.0;
  facts.machine_update_hz = 20.0;
  CHECK_EQUAL(2'000'000, period_ns(facts));
  CHECK_EQUAL(50'000'000, update_ns(facts));
}
