// The request rules (request_rules.hpp) a controller checks every display request against, and the
// display checks first: each parameter's unit and command, each request's cycle command (always from
// the display), a Set beyond the board's limits refused with the reason, and reset, pause and resume
// refused while the newest telemetry says the cycle cannot take them. Plain functions, plain data.
#include <cmath>
#include <limits>
#include <string>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/display_link/request_rules.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::display_link;

TEST_GROUP(RequestRules){};

TEST(RequestRules, EachParameterHasItsUnitAndTheCommandThatSetsIt) {
  STRCMP_EQUAL("N/mm", parameter_unit(Parameter::Coupling));
  STRCMP_EQUAL("N", parameter_unit(Parameter::ForceLimit));
  STRCMP_EQUAL("mm/s", parameter_unit(Parameter::SpeedLimit));
  CHECK(command_kind(Parameter::Coupling) == control::CommandKind::SetCoupling);
  CHECK(command_kind(Parameter::ForceLimit) == control::CommandKind::SetForceLimit);
  CHECK(command_kind(Parameter::SpeedLimit) == control::CommandKind::SetSpeedLimit);
}

// Everything a display asks reaches the cycle as from the display (the journal says where a stop
// came from); a Start is never a cycle command, and anything not a command is taken as a stop.
TEST(RequestRules, EachRequestBecomesItsCycleCommandFromTheDisplay) {
  const control::Command set = command_of({RequestKind::Set, Parameter::SpeedLimit, 0.75});
  CHECK(set.kind == control::CommandKind::SetSpeedLimit);
  DOUBLES_EQUAL(0.75, set.value, 0.0);
  CHECK(set.source == control::CommandSource::Display);
  const RequestKind kinds[] = {RequestKind::Reset, RequestKind::Stop, RequestKind::Pause, RequestKind::Resume,
                               RequestKind::Start};
  const control::CommandKind commands[] = {control::CommandKind::Reset, control::CommandKind::Stop,
                                           control::CommandKind::Pause, control::CommandKind::Resume,
                                           control::CommandKind::Stop};
  for (int i = 0; i < 5; ++i) {
    const control::Command command = command_of({kinds[i], Parameter::ForceLimit, 9.0});
    CHECK(command.kind == commands[i]);
    DOUBLES_EQUAL(0.0, command.value, 0.0);  // only a Set carries its value
    CHECK(command.source == control::CommandSource::Display);
  }
}

TEST(RequestRules, ParametersBeyondTheBoardsLimitsAreRefusedWithTheReason) {
  const RequestLimits limits{5.0, 1.0, 0.05, 2.0};
  CHECK(refusal({RequestKind::Set, Parameter::ForceLimit, 5.0}, limits).empty());
  CHECK(refusal({RequestKind::Set, Parameter::ForceLimit, 0.5}, limits).empty());
  const std::string fifty = refusal({RequestKind::Set, Parameter::ForceLimit, 50.0}, limits);
  STRCMP_CONTAINS("50 N is above the board's force limit of 5 N", fifty.c_str());
  STRCMP_CONTAINS("above what the mill follows, 1 mm/s", refusal({RequestKind::Set, Parameter::SpeedLimit, 2.0}, limits).c_str());
  CHECK(refusal({RequestKind::Set, Parameter::SpeedLimit, 0.5}, limits).empty());
  STRCMP_CONTAINS("outside the coupling's range of 0.05 to 2 N/mm",
                  refusal({RequestKind::Set, Parameter::Coupling, 3.0}, limits).c_str());
  STRCMP_CONTAINS("must be a positive number", refusal({RequestKind::Set, Parameter::Coupling, -1.0}, limits).c_str());
  STRCMP_CONTAINS("must be a positive number",
                  refusal({RequestKind::Set, Parameter::ForceLimit, std::nan("")}, limits).c_str());
  CHECK(refusal({RequestKind::Reset, Parameter::Coupling, 0.0}, limits).empty());
}

// The edges: the coupling's range is closed at both ends; below it is refused as well as above; an
// infinite value or zero is not a number the cycle can take.
TEST(RequestRules, TheLimitsAreClosedRangesAndZeroOrInfinityIsRefusedNamingTheUnit) {
  const RequestLimits limits{5.0, 1.0, 0.05, 2.0};
  CHECK(refusal({RequestKind::Set, Parameter::Coupling, 0.05}, limits).empty());
  CHECK(refusal({RequestKind::Set, Parameter::Coupling, 2.0}, limits).empty());
  STRCMP_EQUAL("0.01 N/mm is outside the coupling's range of 0.05 to 2 N/mm",
               refusal({RequestKind::Set, Parameter::Coupling, 0.01}, limits).c_str());
  CHECK(refusal({RequestKind::Set, Parameter::SpeedLimit, 1.0}, limits).empty());
  STRCMP_EQUAL("speed_limit must be a positive number of mm/s",
               refusal({RequestKind::Set, Parameter::SpeedLimit, 0.0}, limits).c_str());
  STRCMP_EQUAL("force_limit must be a positive number of N",
               refusal({RequestKind::Set, Parameter::ForceLimit, std::numeric_limits<double>::infinity()}, limits).c_str());
}

TEST(RequestRules, APauseOrAResumeIsRefusedWhenTheCycleCannotTakeIt) {
  control::Telemetry t{};
  STRCMP_EQUAL("the job has not started yet", pause_refusal(RequestKind::Pause, false, t).c_str());
  STRCMP_EQUAL("", pause_refusal(RequestKind::Pause, true, t).c_str());
  STRCMP_EQUAL("not paused", pause_refusal(RequestKind::Resume, true, t).c_str());
  t.paused = true;
  STRCMP_EQUAL("already paused", pause_refusal(RequestKind::Pause, true, t).c_str());
  STRCMP_EQUAL("", pause_refusal(RequestKind::Resume, true, t).c_str());
  t.safe_reason = control::SafeReason::Stopped;
  STRCMP_CONTAINS("in its safe state (stopped)", pause_refusal(RequestKind::Resume, true, t).c_str());
}

TEST(RequestRules, AResetMayBeAskedOnlyInASafeStateWithTheHandleStillNearTheTool) {
  const ResetRule rule{0.2, 2.0};
  control::Telemetry t{};
  STRCMP_CONTAINS("not in a safe state", reset_refusal(false, t, rule).c_str());
  STRCMP_CONTAINS("not in a safe state", reset_refusal(true, t, rule).c_str());
  t.safe_reason = control::SafeReason::DeviceStale;
  t.device_still_s = 0.1;
  t.device_to_tool_mm = 1.0;
  STRCMP_EQUAL("hold the handle still (200 ms)", reset_refusal(true, t, rule).c_str());
  t.device_still_s = 1.0;
  t.device_to_tool_mm = 12.0;
  STRCMP_EQUAL("bring the handle to the virtual tool: 12.0 mm away, at most 2.0 mm", reset_refusal(true, t, rule).c_str());
  t.device_to_tool_mm = 2.0;  // at the distance is near enough
  STRCMP_EQUAL("", reset_refusal(true, t, rule).c_str());
  t.device_still_s = 0.2;  // and still for just long enough
  STRCMP_EQUAL("", reset_refusal(true, t, rule).c_str());
  STRCMP_CONTAINS("not in a safe state", reset_refusal(false, t, rule).c_str());  // no telemetry yet
}

// Issue 29: the wall's feel. Zero is a value (none, the cap alone), the damping is bounded by what
// the cycle renders stably, friction is a coefficient of 0 to 1, the speed limiting 0 or 1.
TEST(RequestRules, TheWallsFeelTakesZeroAndIsBoundedByItsOwnRange) {
  RequestLimits limits;
  limits.max_damping_n_s_per_m = 100.0;
  CHECK(command_kind(Parameter::Damping) == control::CommandKind::SetDamping);
  CHECK(command_kind(Parameter::Friction) == control::CommandKind::SetFriction);
  CHECK(command_kind(Parameter::SpeedLimiting) == control::CommandKind::SetSpeedLimiting);
  STRCMP_EQUAL("N s/m", parameter_unit(Parameter::Damping));
  for (const Parameter p : {Parameter::Damping, Parameter::Friction, Parameter::SpeedLimiting}) {
    CHECK(refusal({RequestKind::Set, p, 0.0}, limits).empty());
    CHECK(refusal({RequestKind::Set, p, 1.0}, limits).empty());
    CHECK_FALSE(refusal({RequestKind::Set, p, -0.5}, limits).empty());
    CHECK_FALSE(refusal({RequestKind::Set, p, std::nan("")}, limits).empty());
  }
  CHECK(refusal({RequestKind::Set, Parameter::Damping, 100.0}, limits).empty());
  STRCMP_EQUAL("150 N s/m is above the most damping the cycle takes, 100 N s/m",
               refusal({RequestKind::Set, Parameter::Damping, 150.0}, limits).c_str());
  STRCMP_EQUAL("damping must be a number of at least 0", refusal({RequestKind::Set, Parameter::Damping, -1.0}, limits).c_str());
  CHECK(refusal({RequestKind::Set, Parameter::Friction, 0.5}, limits).empty());
  STRCMP_EQUAL("a friction coefficient of 1.2 is outside 0 to 1",
               refusal({RequestKind::Set, Parameter::Friction, 1.2}, limits).c_str());
  STRCMP_EQUAL("speed limiting 0.5: expected 0 (the cap) or 1 (the penalty)",
               refusal({RequestKind::Set, Parameter::SpeedLimiting, 0.5}, limits).c_str());
  STRCMP_EQUAL("speed limiting -1: expected 0 (the cap) or 1 (the penalty)",
               refusal({RequestKind::Set, Parameter::SpeedLimiting, -1.0}, limits).c_str());
  const control::Command penalty = command_of({RequestKind::Set, Parameter::SpeedLimiting, 1.0});
  CHECK(penalty.kind == control::CommandKind::SetSpeedLimiting);
  DOUBLES_EQUAL(1.0, penalty.value, 0.0);
}
