// The simulation board's facts (board/sim/sim_facts.hpp) for any rig a configuration gives, not only
// the compiled-in one its static_asserts pin: the simulated mill built from a rig's truth (steps,
// backlash, hard stops, switch, power-up in mid-workspace, its direction lines), and the CY545
// driver's differences in the simulation (faster homing, capped at the chip's rate).
#include "board/sim/sim_facts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

TEST_GROUP(SimFacts){};

TEST(SimFacts, TheMillIsBuiltFromTheTruthInSteps) {
  rig::RigFacts truth = rig::kRig;
  truth.steps_per_mm = 100.0;
  truth.backlash_mm = {0.1, 0.2, 0.3};
  truth.mmc4s.step_direction = {1, -1, 1};
  const stencil::sim::MillConfig mill = mill_config(truth);
  DOUBLES_EQUAL(100.0, mill.steps_per_mm, 0.0);
  CHECK_EQUAL(10, mill.axes[0].backlash_steps);
  CHECK_EQUAL(30, mill.axes[2].backlash_steps);
  CHECK_EQUAL(-300, mill.axes[0].travel_min_steps);  // 3 mm below the switch
  CHECK_EQUAL(5500, mill.axes[0].travel_max_steps);  // 50 + 5 mm
  CHECK_EQUAL(3000, mill.axes[1].travel_max_steps);  // 25 + 5 mm
  CHECK_EQUAL(0, mill.axes[1].home_switch_edge_steps);
  CHECK_EQUAL(2500, mill.axes[0].initial_position_steps);  // mid-workspace
  CHECK_EQUAL(1250, mill.axes[2].initial_position_steps);
  CHECK_EQUAL(-1, mill.axes[1].motor_direction);
  CHECK_EQUAL(1, mill.axes[0].motor_direction);
}

TEST(SimFacts, HomingRunsFasterButNeverAboveTheChipsRate) {
  rig::RigFacts facts = rig::kRig;
  facts.homing_speed_mm_per_s = 2.0;  // 1280 steps/s on the rig: 25 times is past 27000
  const hal::cy545::Cy545Config config = link_config(false, facts);
  CHECK_EQUAL(27000U, config.motion.homing_rate);
  CHECK_EQUAL(2000U, config.motion.homing_slow_rate);
  CHECK_FALSE(config.wiring.channel_lines_latch_data);
  CHECK_EQUAL(0, config.command_settle_ns);
}

TEST(SimFacts, OnlyARealTimeRunWaitsLongerForAReply) {
  CHECK_EQUAL(5 * link_config(false).reply_timeout_ns, link_config(true).reply_timeout_ns);
}
