// What the rig's run tells the operator at the terminal (board/sherline_suzuki/operator_terminal):
// the mill's stop once, each safe state with where it came from and the way out, a pause and its
// end, a refused reset with the reason, and the line typed at the terminal forwarded as a command
// from the terminal. Against the spy machine link and telemetry frames written here.
#include <optional>
#include <string>
#include <vector>

#include "board/sherline_suzuki/operator_terminal.hpp"
#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/core/control/machine_side.hpp"
#include "tests/fakes/spy_machine_link.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sherline_suzuki;

namespace {

constexpr hal::MonotonicNs kLongAfter = 1'000'000'000'000;

// A machine side on the spy, and a job whose progress lines are kept.
struct Terminal {
  test::LoadedPart loaded{test::default_part(), 1};
  test::SpyMachineLink link;
  control::MachineHandoffRing handoffs;
  control::MachineEventRing events;
  control::MachineSide machine{loaded.part, link, rig_frames(WorkOffset{}), kPlannerLimits, handoffs, events};
  std::vector<std::string> lines;
  RigJob job;
  Terminal() {
    job.progress = [this](const std::string& line) { lines.push_back(line); };
  }
};

control::Telemetry quiet_frame() {
  control::Telemetry frame{};
  frame.safe_reason = control::SafeReason::None;
  frame.last_reset = control::ResetOutcome::Accepted;
  return frame;
}

}  // namespace

TEST_GROUP(OperatorTerminal){};

TEST(OperatorTerminal, SaysNothingWhileTheMillCutsThenTheStopOnce) {
  Terminal t;
  OperatorTerminal terminal(t.job, t.machine);
  CHECK_TRUE(t.machine.start(kLongAfter));
  terminal.after_machine_update();
  CHECK_EQUAL(0U, t.lines.size());
  t.machine.shut_down(kLongAfter);
  CHECK_TRUE(t.machine.stop_confirmed());
  terminal.after_machine_update();
  terminal.after_machine_update();
  CHECK_EQUAL(1U, t.lines.size());
  STRCMP_EQUAL("the mill is stopped: spindle and drivers off, confirmed by the controller", t.lines[0].c_str());
}

TEST(OperatorTerminal, ASafeStateIsToldOnceWithItsSourceAndItsEnd) {
  Terminal t;
  OperatorTerminal terminal(t.job, t.machine);
  control::Telemetry frame = quiet_frame();
  terminal.on_telemetry(frame);
  CHECK_EQUAL(0U, t.lines.size());
  frame.safe_reason = control::SafeReason::PoseJump;
  frame.safe_source = control::CommandSource::Cycle;
  terminal.on_telemetry(frame);
  terminal.on_telemetry(frame);  // the same state: not told again
  CHECK_EQUAL(1U, t.lines.size());
  STRCMP_CONTAINS("SAFE STATE: pose_jump (from cycle)", t.lines[0].c_str());
  STRCMP_CONTAINS("type 'reset'", t.lines[0].c_str());
  frame.safe_reason = control::SafeReason::None;
  terminal.on_telemetry(frame);
  CHECK_EQUAL(2U, t.lines.size());
  STRCMP_CONTAINS("force restored", t.lines[1].c_str());
}

TEST(OperatorTerminal, APauseAndItsEndAreTold) {
  Terminal t;
  OperatorTerminal terminal(t.job, t.machine);
  control::Telemetry frame = quiet_frame();
  frame.paused = true;
  terminal.on_telemetry(frame);
  frame.paused = false;
  terminal.on_telemetry(frame);
  CHECK_EQUAL(2U, t.lines.size());
  STRCMP_CONTAINS("PAUSED", t.lines[0].c_str());
  STRCMP_EQUAL("resumed", t.lines[1].c_str());
}

TEST(OperatorTerminal, ARefusedResetIsToldWithWhyAnAcceptedOneIsNot) {
  Terminal t;
  OperatorTerminal terminal(t.job, t.machine);
  control::Telemetry frame = quiet_frame();
  frame.reset_requests = 1;
  frame.last_reset = control::ResetOutcome::DeviceFarFromTool;
  terminal.on_telemetry(frame);
  CHECK_EQUAL(1U, t.lines.size());
  STRCMP_EQUAL("reset refused: device_far_from_tool", t.lines[0].c_str());
  frame.reset_requests = 2;
  frame.last_reset = control::ResetOutcome::Accepted;
  terminal.on_telemetry(frame);
  CHECK_EQUAL(1U, t.lines.size());
}

TEST(OperatorTerminal, ACommandTypedGoesIntoTheRingFromTheTerminal) {
  Terminal t;
  std::optional<control::CommandKind> typed = control::CommandKind::Stop;
  t.job.operator_command = [&typed]() {
    const std::optional<control::CommandKind> kind = typed;
    typed.reset();
    return kind;
  };
  OperatorTerminal terminal(t.job, t.machine);
  control::CommandRing commands;
  terminal.forward_requests(commands);
  terminal.forward_requests(commands);  // nothing more typed
  CHECK_EQUAL(1U, commands.size());
  control::Command command{control::CommandKind::Reset, 0.0, control::CommandSource::Program, 0};
  CHECK_TRUE(commands.pop(command));
  CHECK(command.kind == control::CommandKind::Stop);
  CHECK(command.source == control::CommandSource::Terminal);
}

TEST(OperatorTerminal, WithoutAProgressLineNothingIsToldAndNothingBreaks) {
  Terminal t;
  t.job.progress = nullptr;
  OperatorTerminal terminal(t.job, t.machine);
  control::Telemetry frame = quiet_frame();
  frame.safe_reason = control::SafeReason::Stopped;
  terminal.on_telemetry(frame);
  terminal.after_records_pass();
  control::CommandRing commands;
  terminal.forward_requests(commands);
  CHECK_EQUAL(0U, commands.size());
}
