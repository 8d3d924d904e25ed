// The simulated mill: backlash taken up exactly on reversal, home switch edge, hard stops, drivers, spindle.
#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/sim_facts.hpp"
#include "sim/mill/simulated_mill.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
namespace rig = stencil::board::sherline_suzuki;

namespace {

StepOutcome step_n(SimulatedMill& mill, Axis axis, StepDirection direction, int count) {
  StepOutcome last = StepOutcome::moved;
  for (int i = 0; i < count; ++i) last = mill.step_motor(axis, direction);
  return last;
}

}  // namespace

TEST_GROUP(SimulatedMill) {
  SimulatedMill mill{stencil::board::sim::kMillConfig};
  void setup() override { mill.set_drivers_enabled(true); }
};

// The simulation board's mill (board/sim/sim_facts.hpp) is the rig's, in motor steps.
TEST(SimulatedMill, TheSimulationBoardsMillComesFromTheRigFacts) {
  const MillConfig config = stencil::board::sim::kMillConfig;
  LONGS_EQUAL(80, config.axes[0].backlash_steps);
  LONGS_EQUAL(32, config.axes[1].backlash_steps);
  LONGS_EQUAL(80, config.axes[2].backlash_steps);
  LONGS_EQUAL(-1920, config.axes[0].travel_min_steps);           // -3 mm
  LONGS_EQUAL(55 * 640, config.axes[0].travel_max_steps);        // 50 + 5 mm
  LONGS_EQUAL(30 * 640, config.axes[1].travel_max_steps);
  LONGS_EQUAL(0, config.axes[2].home_switch_edge_steps);
  DOUBLES_EQUAL(rig::kRig.steps_per_mm, config.steps_per_mm, 0.0);
}

TEST(SimulatedMill, StepsInOneDirectionMoveTheAxisOneStepEach) {
  mill.place_axis(Axis::x, 1000, StepDirection::positive);
  CHECK(step_n(mill, Axis::x, StepDirection::positive, 640) == StepOutcome::moved);
  LONGS_EQUAL(1640, mill.axis_position_steps(Axis::x));
  DOUBLES_EQUAL(1640.0 / 640.0, mill.axis_position_mm(Axis::x), 1e-12);
}

TEST(SimulatedMill, ReversalTakesUpExactlyTheBacklashBeforeTheAxisMoves) {
  const Axis axes[] = {Axis::x, Axis::y, Axis::z};
  const int backlash[] = {80, 32, 80};
  for (int i = 0; i < 3; ++i) {
    const Axis axis = axes[i];
    mill.place_axis(axis, 5000, StepDirection::positive);
    // Reversal to negative: `backlash` motor steps leave the axis where it is ...
    for (int k = 0; k < backlash[i]; ++k) {
      CHECK(mill.step_motor(axis, StepDirection::negative) == StepOutcome::took_up_backlash);
      LONGS_EQUAL(5000, mill.axis_position_steps(axis));
    }
    // ... and the next one moves it.
    CHECK(mill.step_motor(axis, StepDirection::negative) == StepOutcome::moved);
    LONGS_EQUAL(4999, mill.axis_position_steps(axis));
    // Back to positive: the same slack again.
    CHECK(step_n(mill, axis, StepDirection::positive, backlash[i]) == StepOutcome::took_up_backlash);
    LONGS_EQUAL(4999, mill.axis_position_steps(axis));
    CHECK(mill.step_motor(axis, StepDirection::positive) == StepOutcome::moved);
    LONGS_EQUAL(5000, mill.axis_position_steps(axis));
    LONGS_EQUAL(2 * backlash[i], mill.steps_taking_up_backlash(axis));
  }
}

TEST(SimulatedMill, NoSlackIsTakenUpWhenTheDirectionDoesNotChange) {
  mill.place_axis(Axis::y, 100, StepDirection::negative);
  CHECK(step_n(mill, Axis::y, StepDirection::negative, 10) == StepOutcome::moved);
  LONGS_EQUAL(90, mill.axis_position_steps(Axis::y));
  LONGS_EQUAL(0, mill.steps_taking_up_backlash(Axis::y));
}

TEST(SimulatedMill, ARoundTripWithPartialReversalKeepsTheNutInsideThePlay) {
  mill.place_axis(Axis::x, 0, StepDirection::positive);
  step_n(mill, Axis::x, StepDirection::negative, 40);   // half the slack
  step_n(mill, Axis::x, StepDirection::positive, 40);   // back: no motion at all
  LONGS_EQUAL(0, mill.axis_position_steps(Axis::x));
  CHECK(mill.step_motor(Axis::x, StepDirection::positive) == StepOutcome::moved);
  LONGS_EQUAL(1, mill.axis_position_steps(Axis::x));
}

TEST(SimulatedMill, HomeSwitchIsClosedOnlyBelowItsEdge) {
  mill.place_axis(Axis::z, 2, StepDirection::negative);
  CHECK_FALSE(mill.home_switch_closed(Axis::z));
  mill.step_motor(Axis::z, StepDirection::negative);  // 1
  CHECK_FALSE(mill.home_switch_closed(Axis::z));
  mill.step_motor(Axis::z, StepDirection::negative);  // 0: the edge itself is open
  CHECK_FALSE(mill.home_switch_closed(Axis::z));
  mill.step_motor(Axis::z, StepDirection::negative);  // -1
  CHECK(mill.home_switch_closed(Axis::z));
  CHECK_FALSE(mill.home_switch_closed(Axis::x));
}

TEST(SimulatedMill, HardStopsStallTheMotorAndCountTheLostSteps) {
  const MillAxisConfig& y = mill.config().axes[1];
  mill.place_axis(Axis::y, y.travel_max_steps - 3, StepDirection::positive);
  CHECK(step_n(mill, Axis::y, StepDirection::positive, 3) == StepOutcome::moved);
  CHECK(mill.at_travel_limit(Axis::y));
  const std::int64_t motor = mill.motor_position_steps(Axis::y);
  CHECK(step_n(mill, Axis::y, StepDirection::positive, 10) == StepOutcome::stalled_at_limit);
  LONGS_EQUAL(y.travel_max_steps, mill.axis_position_steps(Axis::y));
  LONGS_EQUAL(motor, mill.motor_position_steps(Axis::y));
  LONGS_EQUAL(10, mill.steps_lost_at_limits(Axis::y));
  // Leaving the stop works at once after the slack.
  CHECK(step_n(mill, Axis::y, StepDirection::negative, 33) == StepOutcome::moved);
  LONGS_EQUAL(y.travel_max_steps - 1, mill.axis_position_steps(Axis::y));
  CHECK_FALSE(mill.at_travel_limit(Axis::y));

  mill.place_axis(Axis::x, mill.config().axes[0].travel_min_steps, StepDirection::negative);
  CHECK(mill.step_motor(Axis::x, StepDirection::negative) == StepOutcome::stalled_at_limit);
  LONGS_EQUAL(-1920, mill.axis_position_steps(Axis::x));
}

TEST(SimulatedMill, DisabledDriversIgnoreSteps) {
  mill.place_axis(Axis::x, 10, StepDirection::positive);
  mill.set_drivers_enabled(false);
  CHECK(mill.step_motor(Axis::x, StepDirection::positive) == StepOutcome::drivers_disabled);
  LONGS_EQUAL(10, mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(10 + 80, mill.motor_position_steps(Axis::x));
  LONGS_EQUAL(1, mill.steps_ignored_while_disabled());
}

TEST(SimulatedMill, PowersUpWithDriversOffSpindleOffInMidWorkspace) {
  SimulatedMill fresh{stencil::board::sim::kMillConfig};
  CHECK_FALSE(fresh.drivers_enabled());
  CHECK_FALSE(fresh.spindle_on());
  LONGS_EQUAL(25 * 640, fresh.axis_position_steps(Axis::x));
  LONGS_EQUAL(8000, fresh.axis_position_steps(Axis::y));
  fresh.set_spindle_on(true);
  CHECK(fresh.spindle_on());
}

TEST(SimulatedMill, TrueToolPositionInvertsTheTableAxes) {
  mill.place_axis(Axis::x, 640, StepDirection::positive);
  mill.place_axis(Axis::y, 1280, StepDirection::positive);
  mill.place_axis(Axis::z, 320, StepDirection::positive);
  const auto tool = mill.true_tool_position_in_table_mm();
  DOUBLES_EQUAL(-1.0, tool[0], 1e-12);
  DOUBLES_EQUAL(-2.0, tool[1], 1e-12);
  DOUBLES_EQUAL(0.5, tool[2], 1e-12);
}
