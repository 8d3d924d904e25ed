// What follows from the rig's facts (board/sherline_suzuki/rig_facts.hpp) for any rig a configuration
// describes, not only the compiled-in one its static_asserts pin: rounding to steps, the travel past
// the workspace, the largest backlash, the planner's and the CY545's figures, the device's range.
#include <cmath>
#include <string>

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

// ---- A LinuxCNC mill: one G1 from rest to rest an update, its axes' limits from LinuxCNC's INI.

namespace {

// The test INI's mill (tests/board/sherline_suzuki/linuxcnc_test_mill.ini): 5 mm/s and 200 mm/s^2 on
// every axis, driven by LinuxCNC at 8 updates a second.
RigFacts linuxcnc_mill() {
  RigFacts facts = kRig;
  facts.controller = MachineController::Linuxcnc;
  facts.machine_update_hz = 8.0;
  facts.linuxcnc.connect_password = fixed_text<32>("SimMillHello");
  facts.linuxcnc.enable_password = fixed_text<32>("SimMillEnable");
  facts.linuxcnc.max_velocity_mm_per_s = {5.0, 5.0, 5.0};
  facts.linuxcnc.max_acceleration_mm_per_s2 = {200.0, 200.0, 200.0};
  return facts;
}

}  // namespace

TEST(RigFacts, AnAxisFromRestToRestAcceleratesAndBrakesHalfTheTimeUntilItReachesItsTopSpeed) {
  // 5 mm/s at 200 mm/s^2: the top speed is reached after 25 ms, so a move shorter than 50 ms is a
  // triangle, a T^2 / 4 ...
  DOUBLES_EQUAL(200.0 * 0.04 * 0.04 / 4.0, rest_to_rest_mm(0.04, 5.0, 200.0), 1e-15);   // 0.08 mm
  // ... the two agree at 2 v / a (v^2 / a = 0.125 mm) ...
  DOUBLES_EQUAL(0.125, rest_to_rest_mm(0.05, 5.0, 200.0), 1e-15);
  // ... and a longer one cruises: v (T - v / a).
  DOUBLES_EQUAL(0.5, rest_to_rest_mm(0.125, 5.0, 200.0), 1e-15);                          // 5 * (0.125 - 0.025)
  DOUBLES_EQUAL(50.0 * 0.125 * 0.125 / 4.0, rest_to_rest_mm(0.125, 5.0, 50.0), 1e-15);   // 0.1953125: a triangle
}

TEST(RigFacts, ThePlannerSpendsWhatTheSlowestLinuxcncAxisCoversInOneUpdate) {
  const motion::PlannerLimits limits = planner_limits(linuxcnc_mill());
  // T = 1/8 s: each axis covers 5 * (0.125 - 5/200) = 0.5 mm from rest to rest, 4 mm/s over the update.
  CHECK(limits.path == motion::MachinePath::Straight);
  DOUBLES_EQUAL(0.125, limits.update_period_s, 0.0);
  DOUBLES_EQUAL(4.0, limits.speed.max_axis_speed_mm_per_s, 1e-12);
  DOUBLES_EQUAL(3.0 * 4.0 * 640.0, limits.speed.step_rate_steps_per_s, 1e-9);  // 7680: the sum is not limited
  DOUBLES_EQUAL(640.0, limits.speed.steps_per_mm, 0.0);
  CHECK_EQUAL(0, limits.backlash_steps[0]);  // LinuxCNC takes up its own
  CHECK_EQUAL(0, limits.backlash_steps[1]);
  CHECK_EQUAL(0, limits.backlash_steps[2]);
  CHECK(motion::follow_fallback_fits(limits));  // 320 steps an axis an update, against 9

  RigFacts slow_z = linuxcnc_mill();
  slow_z.linuxcnc.max_acceleration_mm_per_s2[2] = 50.0;  // Z: 0.1953125 mm, a triangle
  DOUBLES_EQUAL(0.1953125 / 0.125, planner_limits(slow_z).speed.max_axis_speed_mm_per_s, 1e-12);  // 1.5625 mm/s
  DOUBLES_EQUAL(3.0 * 1.5625 * 640.0, planner_limits(slow_z).speed.step_rate_steps_per_s, 1e-9);  // 3000
}

TEST(RigFacts, TheTrajectorysTopSpeedCapsEveryLinuxcncAxis) {
  RigFacts facts = linuxcnc_mill();
  facts.linuxcnc.max_linear_velocity_mm_per_s = 2.0;
  // 2 mm/s: 2 * (0.125 - 2/200) = 0.23 mm an update, 1.84 mm/s.
  DOUBLES_EQUAL(1.84, planner_limits(facts).speed.max_axis_speed_mm_per_s, 1e-12);
  facts.linuxcnc.max_linear_velocity_mm_per_s = 50.0;  // above every axis's: no cap
  DOUBLES_EQUAL(4.0, planner_limits(facts).speed.max_axis_speed_mm_per_s, 1e-12);
}

TEST(RigFacts, TheCy545sPlannerLimitsAreUnchanged) {
  const motion::PlannerLimits limits = planner_limits(kRig);
  CHECK(limits.path == motion::MachinePath::Staircase);
  DOUBLES_EQUAL(1.4, limits.speed.max_axis_speed_mm_per_s, 0.0);
  DOUBLES_EQUAL(1000.0, limits.speed.step_rate_steps_per_s, 0.0);
  CHECK(kRig.controller == MachineController::Cy545);
  // The LinuxCNC facts do not count for a CY545 rig.
  RigFacts facts = kRig;
  facts.linuxcnc.max_velocity_mm_per_s = {1.0, 1.0, 1.0};
  DOUBLES_EQUAL(1.4, planner_limits(facts).speed.max_axis_speed_mm_per_s, 0.0);
}

TEST(RigFacts, TheLinuxcncLinkGetsTheRigsAddressPasswordsGridTravelLongestMoveAndFeed) {
  RigFacts facts = linuxcnc_mill();
  facts.linuxcnc.max_velocity_mm_per_s[1] = 6.0;  // Y the fastest: 6 * (0.125 - 0.03) = 0.57 mm an update
  const hal::linuxcnc::LinuxcncConfig config = linuxcnc_config(facts);
  STRCMP_EQUAL("127.0.0.1", config.address.data());
  CHECK_EQUAL(5007, config.port);
  STRCMP_EQUAL("SimMillHello", config.connect_password.data());
  STRCMP_EQUAL("SimMillEnable", config.enable_password.data());
  DOUBLES_EQUAL(640.0, config.steps_per_mm, 0.0);
  CHECK(config.travel_mm == kRig.workspace_mm);
  DOUBLES_EQUAL(0.57 + 1.0 / 640.0, config.max_move_mm, 1e-12);
  DOUBLES_EQUAL(60.0 * std::sqrt(3.0) * 6.0, config.feed_mm_per_min, 1e-9);  // a path speed: sqrt(3) * 6 mm/s
  STRCMP_EQUAL("", std::string(hal::linuxcnc::check_linuxcnc_config(config)).c_str());
  // The test INI's mill: every axis 0.5 mm an update, F300.
  DOUBLES_EQUAL(0.5 + 1.0 / 640.0, linuxcnc_config(linuxcnc_mill()).max_move_mm, 1e-12);
  DOUBLES_EQUAL(60.0 * std::sqrt(3.0) * 5.0, linuxcnc_config(linuxcnc_mill()).feed_mm_per_min, 1e-9);
}
