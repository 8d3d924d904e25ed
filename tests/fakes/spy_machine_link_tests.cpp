// The spy mill's own tests: it writes down every call in order with its arguments, refuses what
// hal/machine_link.hpp says a link refuses (as the CY545 link does), answers as scripted, and keeps a
// latched fault for good. The machine side's tests trust it on each of these.
#include <atomic>
#include <cstdint>
#include <vector>

#include "hal/machine_link.hpp"
#include "tests/fakes/spy_machine_link.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using test::MachineCall;

namespace {

constexpr hal::MonotonicNs kDeadline = 123'456'789;

hal::MachineTarget target(std::int32_t x, std::int32_t y, std::int32_t z, bool cutting = true) {
  return {{x, y, z}, {2, 0, 1}, cutting};
}

// Started, homed and the spindle on: what a machine side has before its first move.
void ready_to_cut(test::SpyMachineLink& link) {
  CHECK_TRUE(link.start(kDeadline).done);
  CHECK_TRUE(link.home(kDeadline).done);
  CHECK_TRUE(link.set_spindle(true, kDeadline).done);
}

void check_refused(hal::MachineRefusal expected, const hal::MachineResult& result) {
  CHECK_FALSE(result.done);
  LONGS_EQUAL(static_cast<int>(expected), static_cast<int>(result.refusal));
  LONGS_EQUAL(static_cast<int>(hal::MachineFault::None), static_cast<int>(result.fault));
}

}  // namespace

TEST_GROUP(SpyMachineLink){};

TEST(SpyMachineLink, WritesDownEveryCallInOrderWithItsArguments) {
  test::SpyMachineLink link;
  const std::atomic<bool> abort{false};
  link.abort_on(&abort);
  ready_to_cut(link);
  CHECK_TRUE(link.move(target(10, -20, 30), 1000).done);
  CHECK_TRUE(link.verify(1001).done);
  CHECK_TRUE(link.keep_alive(1002).done);
  link.hold();
  link.resume();
  CHECK_TRUE(link.declare_home(1003).done);
  CHECK_TRUE(link.set_spindle(false, 1004).done);
  CHECK_TRUE(link.stop(1005).done);

  const std::vector<MachineCall> expected{MachineCall::AbortOn, MachineCall::Start,     MachineCall::Home,
                                          MachineCall::SetSpindle, MachineCall::Move,  MachineCall::Verify,
                                          MachineCall::KeepAlive, MachineCall::Hold,   MachineCall::Resume,
                                          MachineCall::DeclareHome, MachineCall::SetSpindle, MachineCall::Stop};
  CHECK(expected == link.call_kinds());
  const std::vector<test::SpyCall>& calls = link.calls();
  POINTERS_EQUAL(&abort, link.abort_flag());
  LONGS_EQUAL(kDeadline, calls[1].deadline_ns);
  CHECK_TRUE(calls[3].spindle_on);
  LONGS_EQUAL(10, calls[4].target.motor_steps[0]);
  LONGS_EQUAL(-20, calls[4].target.motor_steps[1]);
  LONGS_EQUAL(30, calls[4].target.motor_steps[2]);
  LONGS_EQUAL(2, calls[4].target.order[0]);
  CHECK_TRUE(calls[4].target.cutting);
  LONGS_EQUAL(1000, calls[4].deadline_ns);
  LONGS_EQUAL(1001, calls[5].deadline_ns);
  LONGS_EQUAL(1002, calls[6].deadline_ns);
  LONGS_EQUAL(1003, calls[9].deadline_ns);
  CHECK_FALSE(calls[10].spindle_on);
  LONGS_EQUAL(1004, calls[10].deadline_ns);
  LONGS_EQUAL(1005, calls[11].deadline_ns);
  for (const test::SpyCall& call : calls) {
    CHECK_TRUE(call.result.done);
  }
  LONGS_EQUAL(1, link.keep_alives());
  LONGS_EQUAL(1, link.stops());
  STRCMP_EQUAL("declare_home", test::machine_call_name(calls[9].kind));
}

TEST(SpyMachineLink, AcceptedMovesReachTheMillAtOnceAndTheCallbackSeesEachBeforeItIsStored) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  std::vector<std::size_t> stored_before;
  link.on_move = [&](const hal::MachineTarget&) { stored_before.push_back(link.moves().size()); };
  CHECK_TRUE(link.move(target(1, 2, 3), kDeadline).done);
  CHECK_TRUE(link.move(target(4, 5, 6), kDeadline).done);
  LONGS_EQUAL(2, link.moves().size());
  LONGS_EQUAL(4, link.moves()[1].motor_steps[0]);
  CHECK((std::vector<std::size_t>{0, 1}) == stored_before);
  const hal::MachineStatus status = link.status();
  LONGS_EQUAL(2, status.moves_done);
  LONGS_EQUAL(6, status.commanded_steps[2]);
}

TEST(SpyMachineLink, MovesCanBeLeftRunningUntilTheTestCompletesThem) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  link.complete_moves_at_once = false;
  CHECK_TRUE(link.move(target(1, 0, 0), kDeadline).done);
  CHECK_TRUE(link.move(target(2, 0, 0), kDeadline).done);
  LONGS_EQUAL(0, link.status().moves_done);
  link.complete_moves(1);
  LONGS_EQUAL(1, link.status().moves_done);
  link.complete_moves(5);  // no more than were sent
  LONGS_EQUAL(2, link.status().moves_done);
}

TEST(SpyMachineLink, StartsOpenAndRefusesHomingOrMovingBeforeStart) {
  test::SpyMachineLink link;
  CHECK(link.status().state == hal::MachineState::Open);
  check_refused(hal::MachineRefusal::NotHomed, link.home(kDeadline));
  check_refused(hal::MachineRefusal::NotHomed, link.declare_home(kDeadline));
  check_refused(hal::MachineRefusal::NotHomed, link.set_spindle(true, kDeadline));
  check_refused(hal::MachineRefusal::NotHomed, link.keep_alive(kDeadline));
  check_refused(hal::MachineRefusal::NotHomed, link.move(target(1, 0, 0, false), kDeadline));
  CHECK_TRUE(link.start(kDeadline).done);
  CHECK(link.status().state == hal::MachineState::Ready);
  CHECK_FALSE(link.status().homed);
  check_refused(hal::MachineRefusal::NotHomed, link.move(target(1, 0, 0, false), kDeadline));
  LONGS_EQUAL(0, link.moves().size());
  LONGS_EQUAL(7, link.calls().size());  // refused calls are written down too
}

TEST(SpyMachineLink, RefusesACuttingMoveWhileTheSpindleIsOffButNotARapidOne) {
  test::SpyMachineLink link;
  CHECK_TRUE(link.start(kDeadline).done);
  CHECK_TRUE(link.home(kDeadline).done);
  check_refused(hal::MachineRefusal::SpindleOff, link.move(target(1, 0, 0, true), kDeadline));
  CHECK_TRUE(link.move(target(1, 0, 0, false), kDeadline).done);
  LONGS_EQUAL(1, link.moves().size());
  CHECK_FALSE(link.moves()[0].cutting);
}

TEST(SpyMachineLink, RefusesBadTargetsAndMovesLongerThanItsBound) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  check_refused(hal::MachineRefusal::BadTarget, link.move({{1, 0, 0}, {0, 0, 1}, true}, kDeadline));
  check_refused(hal::MachineRefusal::BadTarget, link.move({{1, 0, 0}, {0, 1, 3}, true}, kDeadline));
  check_refused(hal::MachineRefusal::BadTarget, link.move(target(1 << 23, 0, 0), kDeadline));
  link.max_move_steps = 10;
  check_refused(hal::MachineRefusal::TooLong, link.move(target(6, 5, 0), kDeadline));
  CHECK_TRUE(link.move(target(5, 5, 0), kDeadline).done);
  CHECK_TRUE(link.move(target(0, 0, 0), kDeadline).done);  // ten steps back from where it is
  LONGS_EQUAL(2, link.moves().size());
}

TEST(SpyMachineLink, AHoldRefusesMovesUntilResumedAndCountsWhatItRefused) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  link.hold();
  CHECK(link.status().state == hal::MachineState::Held);
  check_refused(hal::MachineRefusal::Held, link.move(target(1, 0, 0), kDeadline));
  check_refused(hal::MachineRefusal::Held, link.move(target(1, 0, 0), kDeadline));
  LONGS_EQUAL(2, link.refused_while_held());
  CHECK_TRUE(link.keep_alive(kDeadline).done);  // the heartbeat goes on while held
  link.resume();
  CHECK(link.status().state == hal::MachineState::Homed);
  CHECK_TRUE(link.move(target(1, 0, 0), kDeadline).done);
  LONGS_EQUAL(1, link.moves().size());
}

TEST(SpyMachineLink, HoldAndResumeChangeNothingOnALinkThatIsNotHomed) {
  test::SpyMachineLink link;
  CHECK_TRUE(link.start(kDeadline).done);
  link.hold();
  CHECK(link.status().state == hal::MachineState::Ready);
  link.resume();
  CHECK(link.status().state == hal::MachineState::Ready);
}

TEST(SpyMachineLink, StopTurnsSpindleAndDriversOffAndWantsHomingAgain) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  CHECK_TRUE(link.move(target(1, 0, 0), kDeadline).done);
  CHECK_TRUE(link.status().drivers_on);
  const hal::MachineResult stopped = link.stop(kDeadline);
  CHECK_TRUE(stopped.done);
  const hal::MachineStatus status = link.status();
  CHECK(status.state == hal::MachineState::Stopped);
  CHECK_FALSE(status.spindle_on);
  CHECK_FALSE(status.drivers_on);
  CHECK_FALSE(status.homed);
  check_refused(hal::MachineRefusal::NotHomed, link.move(target(2, 0, 0, false), kDeadline));
  link.resume();  // a stop is no hold: resume does not undo it
  check_refused(hal::MachineRefusal::NotHomed, link.move(target(2, 0, 0, false), kDeadline));
  CHECK_TRUE(link.home(kDeadline).done);
  CHECK_TRUE(link.move(target(2, 0, 0, false), kDeadline).done);
  LONGS_EQUAL(0, link.status().commanded_steps[1]);
}

TEST(SpyMachineLink, TheNextCallAnswersWhatTheTestScriptedThenTheContractAgain) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  link.answer_next(MachineCall::Move, {false, hal::MachineRefusal::DeadlineTooShort, hal::MachineFault::None});
  link.answer_next(MachineCall::Move, {false, hal::MachineRefusal::TooLong, hal::MachineFault::None});
  check_refused(hal::MachineRefusal::DeadlineTooShort, link.move(target(1, 0, 0), kDeadline));
  check_refused(hal::MachineRefusal::TooLong, link.move(target(1, 0, 0), kDeadline));
  CHECK_TRUE(link.move(target(1, 0, 0), kDeadline).done);
  LONGS_EQUAL(1, link.moves().size());  // the refused ones never reached the mill
  CHECK(link.status().state == hal::MachineState::Homed);  // and a refusal latches nothing
  // A scripted yes is taken even where the contract says no.
  link.hold();
  link.answer_next(MachineCall::Move, {true, hal::MachineRefusal::None, hal::MachineFault::None});
  CHECK_TRUE(link.move(target(2, 0, 0), kDeadline).done);
  LONGS_EQUAL(2, link.moves().size());
  // Each kind has its own queue.
  link.answer_next(MachineCall::KeepAlive, {false, hal::MachineRefusal::DeadlineTooShort, hal::MachineFault::None});
  check_refused(hal::MachineRefusal::Held, link.move(target(3, 0, 0), kDeadline));
  check_refused(hal::MachineRefusal::DeadlineTooShort, link.keep_alive(kDeadline));
  CHECK_TRUE(link.keep_alive(kDeadline).done);
}

TEST(SpyMachineLink, AScriptedFaultLatchesAndEveryLaterCallButStopIsRefusedFaulted) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  link.fail_next(MachineCall::Move, hal::MachineFault::PortClosed);
  const hal::MachineResult failed = link.move(target(1, 0, 0), kDeadline);
  CHECK_FALSE(failed.done);
  LONGS_EQUAL(static_cast<int>(hal::MachineRefusal::None), static_cast<int>(failed.refusal));
  LONGS_EQUAL(static_cast<int>(hal::MachineFault::PortClosed), static_cast<int>(failed.fault));
  LONGS_EQUAL(0, link.moves().size());
  hal::MachineStatus status = link.status();
  CHECK(status.state == hal::MachineState::Fault);
  CHECK(status.fault == hal::MachineFault::PortClosed);
  CHECK_FALSE(status.homed);
  check_refused(hal::MachineRefusal::Faulted, link.move(target(1, 0, 0), kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.keep_alive(kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.verify(kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.set_spindle(true, kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.home(kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.declare_home(kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.start(kDeadline));
  // Stop still turns the outputs off, says so, and leaves the fault latched (the first one).
  link.fail_next(MachineCall::Verify, hal::MachineFault::PositionMismatch);
  const hal::MachineResult stopped = link.stop(kDeadline);
  CHECK_TRUE(stopped.done);
  LONGS_EQUAL(static_cast<int>(hal::MachineFault::PortClosed), static_cast<int>(stopped.fault));
  status = link.status();
  CHECK(status.state == hal::MachineState::Fault);
  CHECK_FALSE(status.spindle_on);
  CHECK_FALSE(status.drivers_on);
  CHECK_FALSE(link.verify(kDeadline).done);
  CHECK(link.status().fault == hal::MachineFault::PortClosed);
}

TEST(SpyMachineLink, AFaultLatchedBetweenCallsRefusesTheNext) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  link.latch_fault(hal::MachineFault::Timeout);
  CHECK(link.status().state == hal::MachineState::Fault);
  check_refused(hal::MachineRefusal::Faulted, link.keep_alive(kDeadline));
  check_refused(hal::MachineRefusal::Faulted, link.move(target(1, 0, 0), kDeadline));
  LONGS_EQUAL(0, link.moves().size());
}

TEST(SpyMachineLink, AStopThatCannotConfirmTheOutputsOffLeavesThemAsTheyWere) {
  test::SpyMachineLink link;
  ready_to_cut(link);
  link.fail_next(MachineCall::Stop, hal::MachineFault::Timeout);
  const hal::MachineResult stopped = link.stop(kDeadline);
  CHECK_FALSE(stopped.done);
  LONGS_EQUAL(static_cast<int>(hal::MachineFault::Timeout), static_cast<int>(stopped.fault));
  const hal::MachineStatus status = link.status();
  CHECK(status.state == hal::MachineState::Fault);
  CHECK_TRUE(status.spindle_on);  // not known off: the operator must cut the power
  CHECK_FALSE(status.homed);
}

TEST(SpyMachineLink, AnAbortAskedBeforeStartOrHomingIsRefusedAbortedWithTheOutputsOff) {
  test::SpyMachineLink link;
  std::atomic<bool> abort{true};
  link.abort_on(&abort);
  check_refused(hal::MachineRefusal::Aborted, link.start(kDeadline));
  CHECK(link.status().state == hal::MachineState::Stopped);
  CHECK_FALSE(link.status().spindle_on);
  CHECK_FALSE(link.status().drivers_on);
  abort.store(false);
  CHECK(link.start(kDeadline).done);
  abort.store(true);
  check_refused(hal::MachineRefusal::Aborted, link.home(kDeadline));
  CHECK(link.status().state == hal::MachineState::Stopped);
  CHECK_FALSE(link.status().homed);
}

TEST(SpyMachineLink, ReportsTheHomingApproachItIsGiven) {
  test::SpyMachineLink link;
  CHECK((std::array<int, 3>{-1, -1, -1}) == link.home_approach());
  link.approach = {1, -1, 1};
  CHECK((std::array<int, 3>{1, -1, 1}) == link.home_approach());
}
