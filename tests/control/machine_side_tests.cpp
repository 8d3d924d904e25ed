// MachineSide against the spy mill (tests/fakes/spy_machine_link.hpp), the hex prism's real tables
// and the real planner: the order of its start (wake, home, spindle), the safe state taken to the
// mill as a hold then a stop within the update that sees it, whatever the machine side was doing, a
// fault the link latches stopping the machine and reaching the cycle, the 3 s stall rule at its exact
// bound, the backlog it reports each update, and the reversal deadband as the mill sees it. The
// record before send and the stall's report have suites of their own
// (machine_side_recording_tests.cpp, machine_side_stall_tests.cpp). Homing Z first is the link's
// (Cy545Motion::homing_order), not the machine side's: it has its test with the CY545 link.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "firmware/core/control/machine_side.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/fakes/spy_machine_link.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using test::MachineCall;

namespace {

constexpr hal::MonotonicNs kUpdateNs = 33'333'333;
constexpr double kStepMm = 1.0 / 640.0;

// A recorder that writes what it is given at once, or holds it unwritten while `slow` is set.
class RecorderSpy final : public control::MachineRecorder {
 public:
  bool refuse_homing = false;
  bool slow = false;
  int commands = 0;
  [[nodiscard]] bool homed(std::int64_t) override { return !refuse_homing; }
  [[nodiscard]] bool command(const control::MachineCommandRecord&) override {
    ++commands;
    return true;
  }
  [[nodiscard]] bool written() const override { return !slow; }
};

// The hex prism's tables, made once for the whole suite (before the leak checker looks: they outlive
// every test).
const tablegen::TableBytes kTableBytes = test::make_table(test::default_part(), test::default_job_options(2));

struct Bench {
  tables::PartTables part{};
  control::MachineHandoffRing handoffs;
  control::MachineEventRing events;
  test::SpyMachineLink link;
  motion::MachineFrames frames;
  motion::PlannerLimits limits{{1.4, 1000.0, 640.0}, 1.0 / 30.0, {80, 32, 80}};
  std::unique_ptr<control::MachineSide> machine;
  hal::MonotonicNs now = 0;
  std::uint64_t cycle = 0;
  Eigen::Vector3d tip;
  std::vector<control::MachineEvent> seen;  // the events of the newest update

  // Home at `home` (world mm; the hex prism's top is at z 6, its centre at x 25, y 12.5).
  explicit Bench(const Eigen::Vector3d& home = Eigen::Vector3d(25.0, 12.5, 20.0))
      : frames{10.0, Eigen::Vector3d::Zero(), home, {-1, -1, -1}, 640.0}, tip(home) {
    CHECK(tables::load_tables({kTableBytes.data(), kTableBytes.size()}, part).ok);
    machine = std::make_unique<control::MachineSide>(part, link, frames, limits, handoffs, events);
  }
  void start() { CHECK_TRUE(machine->start(1'000'000'000)); }
  // One machine update's 33 cycles, the virtual tool moving `per_cycle` each; `safe_at` the cycle
  // (0-32) whose handoff carries the safe state, -1 none.
  void update(const Eigen::Vector3d& per_cycle = Eigen::Vector3d::Zero(), int safe_at = -1, bool paused = false) {
    for (int i = 0; i < 33; ++i) {
      tip += per_cycle;
      CHECK(handoffs.push({++cycle, {tip.x(), tip.y(), tip.z()}, i == safe_at, paused}));
    }
    now += kUpdateNs;
    machine->update(now + 2 * kUpdateNs);
    seen.clear();
    control::MachineEvent event{};
    while (events.pop(event)) {
      seen.push_back(event);
    }
  }
  [[nodiscard]] int seen_count(control::MachineEventKind kind) const {
    int n = 0;
    for (const control::MachineEvent& event : seen) {
      n += event.kind == kind ? 1 : 0;
    }
    return n;
  }
  [[nodiscard]] int backlog() const {
    int percent = -1;
    for (const control::MachineEvent& event : seen) {
      percent = event.kind == control::MachineEventKind::Backlog ? event.backlog_percent : percent;
    }
    return percent;
  }
  // The link's calls from `first` on.
  [[nodiscard]] std::vector<MachineCall> calls_since(std::size_t first) const {
    const std::vector<MachineCall> all = link.call_kinds();
    return {all.begin() + static_cast<std::ptrdiff_t>(first), all.end()};
  }
};

// The safe state arrives in the next update's handoffs at cycle `safe_at`: within that update the
// link is held then stopped, nothing is sent, the cycle hears Stopped (confirmed) and no fault; later
// updates ask nothing more of the link.
void check_safe_state_stops_within_one_update(Bench& bench, int safe_at, const Eigen::Vector3d& per_cycle, bool paused) {
  const std::size_t before = bench.link.calls().size();
  const std::size_t moves = bench.link.moves().size();
  bench.update(per_cycle, safe_at, paused);
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  const std::vector<MachineCall> calls = bench.calls_since(before);
  CHECK(!calls.empty() && calls.back() == MachineCall::Stop);
  CHECK(calls.size() >= 2 && calls[calls.size() - 2] == MachineCall::Hold);
  LONGS_EQUAL(1, bench.link.stops());
  LONGS_EQUAL(moves, bench.link.moves().size());
  LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Stopped));
  LONGS_EQUAL(0, bench.seen_count(control::MachineEventKind::Fault));
  CHECK_TRUE(bench.machine->stop_confirmed());
  const hal::MachineStatus status = bench.link.status();
  CHECK(status.state == hal::MachineState::Stopped);
  CHECK_FALSE(status.spindle_on);
  CHECK_FALSE(status.drivers_on);
  CHECK_FALSE(bench.machine->held());
  const std::size_t after = bench.link.calls().size();
  bench.update(per_cycle);
  LONGS_EQUAL(after, bench.link.calls().size());
  LONGS_EQUAL(0, bench.seen.size());
}

}  // namespace

TEST_GROUP(MachineSide){};

// --- start: wake, home, then the spindle ------------------------------------------------------

TEST(MachineSide, StartWakesTheControllerHomesItThenTurnsTheSpindleOnAndMovesNothing) {
  Bench bench;
  bench.start();
  CHECK((std::vector<MachineCall>{MachineCall::Start, MachineCall::Home, MachineCall::SetSpindle}) == bench.link.call_kinds());
  CHECK_TRUE(bench.link.calls()[2].spindle_on);
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);
  LONGS_EQUAL(0, bench.link.moves().size());
  CHECK((bench.machine->commanded_tip_mm() - bench.frames.home_world_mm).norm() < 1e-12);
}

TEST(MachineSide, AHomingTheLinkRefusesLeavesTheSpindleOffAndTheMillUnmoved) {
  Bench bench;
  bench.link.answer_next(MachineCall::Home, {false, hal::MachineRefusal::Aborted, hal::MachineFault::None});
  CHECK_FALSE(bench.machine->start(1'000'000'000));
  CHECK((std::vector<MachineCall>{MachineCall::Start, MachineCall::Home}) == bench.link.call_kinds());
  CHECK(bench.machine->state() == control::MachineSideState::NotStarted);
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));  // the cycle runs; the machine side does nothing
  LONGS_EQUAL(2, bench.link.calls().size());
  LONGS_EQUAL(0, bench.seen.size());
}

TEST(MachineSide, AControllerThatDoesNotWakeIsNeverHomed) {
  Bench bench;
  bench.link.fail_next(MachineCall::Start, hal::MachineFault::NoAnswer);
  CHECK_FALSE(bench.machine->start(1'000'000'000));
  CHECK((std::vector<MachineCall>{MachineCall::Start}) == bench.link.call_kinds());
  CHECK(bench.machine->fault() == hal::MachineFault::NoAnswer);
}

TEST(MachineSide, TheSpindleStaysOffOnAMillThatIsNotHomed) {
  Bench bench;
  CHECK_TRUE(bench.link.start(0).done);  // awake, not homed: the link itself would let the spindle on
  CHECK_FALSE(bench.machine->start_spindle(1'000'000'000));
  CHECK((std::vector<MachineCall>{MachineCall::Start}) == bench.link.call_kinds());
  CHECK(bench.machine->state() == control::MachineSideState::NotStarted);
}

TEST(MachineSide, AHomingTheRecordRefusesWakesNothing) {
  Bench bench;
  RecorderSpy recorder;
  recorder.refuse_homing = true;
  bench.machine->record_to(&recorder);
  CHECK_FALSE(bench.machine->start(1'000'000'000));
  CHECK_TRUE(bench.machine->record_failed());
  LONGS_EQUAL(0, bench.link.calls().size());
}

// --- the safe state: hold and stop within the update that sees it --------------------------------

// The machine side is told only that the cycle is in its safe state (MachineHandoff::safe_state),
// never why, so every SafeReason reaches it the same way: what varies is where in the update's
// handoffs it comes and what the machine side was doing.
TEST(MachineSide, ASafeStateAtAnyCycleOfTheUpdateStopsTheMillInThatUpdate) {
  for (const int safe_at : {0, 1, 16, 31, 32}) {
    Bench bench;
    bench.start();
    for (int i = 0; i < 5; ++i) {
      bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
    }
    CHECK(!bench.link.moves().empty());
    check_safe_state_stops_within_one_update(bench, safe_at, Eigen::Vector3d(1e-3, 0.0, 0.0), false);
  }
}

TEST(MachineSide, ASafeStateStopsAMillThatStandsAtItsGoal) {
  Bench bench;
  bench.start();
  for (int i = 0; i < 40; ++i) {
    bench.update(i < 5 ? Eigen::Vector3d(1e-3, 0.0, 0.0) : Eigen::Vector3d::Zero());
  }
  CHECK_TRUE(bench.machine->at_goal());
  check_safe_state_stops_within_one_update(bench, 32, Eigen::Vector3d::Zero(), false);
}

TEST(MachineSide, ASafeStateStopsAMillTheOperatorHolds) {
  Bench bench;
  bench.start();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  bench.update(Eigen::Vector3d::Zero(), -1, true);
  CHECK_TRUE(bench.machine->held());
  check_safe_state_stops_within_one_update(bench, 10, Eigen::Vector3d::Zero(), true);
}

TEST(MachineSide, ASafeStateStopsAMillWaitingForTheRecord) {
  Bench bench;
  RecorderSpy recorder;
  recorder.slow = true;
  bench.machine->record_to(&recorder);
  bench.start();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  LONGS_EQUAL(1, recorder.commands);
  CHECK(bench.machine->statistics().held_for_record > 0);
  recorder.slow = false;  // written now, yet the safe state comes first: the held target never goes
  check_safe_state_stops_within_one_update(bench, 20, Eigen::Vector3d(1e-3, 0.0, 0.0), false);
  LONGS_EQUAL(0, bench.link.moves().size());
}

TEST(MachineSide, ASafeStateStopsAMillThatFindsNoWay) {
  Bench bench(Eigen::Vector3d(25.0, 12.5, 7.0));
  bench.start();
  for (int i = 0; i < 40; ++i) {
    bench.update(i == 0 ? Eigen::Vector3d(0.0, 0.0, -0.98 / 33.0) : Eigen::Vector3d::Zero());  // down to z 6.02
  }
  bench.update(Eigen::Vector3d(0.0, 0.0, -0.03 / 33.0));  // to z 5.99, under the prism's top
  for (int i = 0; i < 10 && bench.machine->statistics().blocked == 0; ++i) {
    bench.update();
  }
  CHECK(bench.machine->statistics().blocked > 0);
  check_safe_state_stops_within_one_update(bench, 5, Eigen::Vector3d::Zero(), false);
}

TEST(MachineSide, TheVirtualToolsTipInASafeStateHandoffIsNotFollowed) {
  Bench bench;
  bench.start();
  const std::size_t path = bench.machine->path_left();
  CHECK(bench.handoffs.push({1, {30.0, 12.5, 20.0}, true, false}));
  bench.machine->update(2 * kUpdateNs);
  LONGS_EQUAL(path, bench.machine->path_left());
}

TEST(MachineSide, AStopTheLinkCannotConfirmIsReportedSo) {
  Bench bench;
  bench.start();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  bench.link.fail_next(MachineCall::Stop, hal::MachineFault::Timeout);
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0), 3);
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  CHECK_FALSE(bench.machine->stop_confirmed());
  LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Stopped));
  for (const control::MachineEvent& event : bench.seen) {
    CHECK(event.kind != control::MachineEventKind::Stopped || !event.stop_confirmed);
  }
  CHECK_TRUE(bench.link.status().spindle_on);  // as far as anyone knows: the operator must cut the power
}

TEST(MachineSide, ShutDownStopsACuttingMillWithoutReportingAFault) {
  Bench bench;
  bench.start();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  bench.machine->shut_down(bench.now + kUpdateNs);
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  LONGS_EQUAL(1, bench.link.stops());
  control::MachineEvent event{};
  CHECK_TRUE(bench.events.pop(event));
  CHECK(event.kind == control::MachineEventKind::Stopped);
  CHECK_FALSE(bench.events.pop(event));
  bench.machine->shut_down(bench.now + kUpdateNs);  // once stopped, nothing more
  LONGS_EQUAL(1, bench.link.stops());
}

// --- a fault the link latches --------------------------------------------------------------------

TEST(MachineSide, AFaultTheLinkLatchesOnAMoveStopsTheMillAndTheCycleHearsItFirst) {
  Bench bench;
  bench.start();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  const std::size_t moves = bench.link.moves().size();
  CHECK(moves > 0);
  bench.link.fail_next(MachineCall::Move, hal::MachineFault::PortClosed);
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  CHECK(bench.machine->fault() == hal::MachineFault::PortClosed);
  LONGS_EQUAL(moves, bench.link.moves().size());
  LONGS_EQUAL(1, bench.link.stops());
  CHECK_TRUE(bench.machine->stop_confirmed());  // a faulted link still turns its outputs off
  // Fault (with what the link latched) before Stopped; the backlog came earlier in the update.
  std::vector<control::MachineEventKind> kinds;
  for (const control::MachineEvent& event : bench.seen) {
    if (event.kind != control::MachineEventKind::Backlog) {
      kinds.push_back(event.kind);
    }
  }
  CHECK((std::vector<control::MachineEventKind>{control::MachineEventKind::Fault, control::MachineEventKind::Stopped}) == kinds);
  CHECK(bench.seen[1].fault == hal::MachineFault::PortClosed);
  CHECK_TRUE(bench.seen[2].stop_confirmed);
  const std::size_t calls = bench.link.calls().size();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  LONGS_EQUAL(calls, bench.link.calls().size());
}

TEST(MachineSide, AFaultLatchedBetweenUpdatesIsFoundByTheHeartbeatAndNothingIsSent) {
  Bench bench;
  bench.start();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  const std::size_t moves = bench.link.moves().size();
  bench.link.latch_fault(hal::MachineFault::Timeout);
  const std::size_t before = bench.link.calls().size();
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  CHECK((std::vector<MachineCall>{MachineCall::KeepAlive, MachineCall::Hold, MachineCall::Stop}) == bench.calls_since(before));
  LONGS_EQUAL(moves, bench.link.moves().size());
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Fault));
  for (const control::MachineEvent& event : bench.seen) {
    CHECK(event.kind != control::MachineEventKind::Fault || event.fault == hal::MachineFault::Timeout);
  }
}

TEST(MachineSide, AMoveTheLinkRefusesStopsTheMillAsAFault) {
  Bench bench;
  bench.start();
  bench.link.answer_next(MachineCall::Move, {false, hal::MachineRefusal::TooLong, hal::MachineFault::None});
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  LONGS_EQUAL(0, bench.link.moves().size());
  LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Fault));
  LONGS_EQUAL(0, bench.machine->statistics().updates);
}

// --- the 3 s stall rule --------------------------------------------------------------------------

TEST(MachineSide, NinetyUpdatesWithNoWayAreStillAHoldAndTheNinetyFirstIsTheStall) {
  LONGS_EQUAL(90, control::MachineSide::kMaxBlockedUpdates);  // 3 s at 30 Hz
  Bench bench(Eigen::Vector3d(25.0, 12.5, 7.0));
  bench.start();
  for (int i = 0; i < 40; ++i) {
    bench.update(i == 0 ? Eigen::Vector3d(0.0, 0.0, -0.98 / 33.0) : Eigen::Vector3d::Zero());  // down to z 6.02
  }
  LONGS_EQUAL(0, bench.machine->statistics().blocked);
  bench.update(Eigen::Vector3d(0.0, 0.0, -0.03 / 33.0));  // to z 5.99: no staircase reaches it
  while (bench.machine->statistics().blocked < static_cast<std::uint64_t>(control::MachineSide::kMaxBlockedUpdates)) {
    CHECK(bench.machine->state() == control::MachineSideState::Cutting);
    bench.update();
  }
  CHECK_FALSE(bench.machine->stalled());
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);
  LONGS_EQUAL(0, bench.link.stops());
  bench.update();
  LONGS_EQUAL(91, bench.machine->statistics().blocked);
  CHECK_TRUE(bench.machine->stalled());
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  LONGS_EQUAL(1, bench.link.stops());
  LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Fault));
  CHECK(bench.machine->fault() == hal::MachineFault::None);  // the planner's, not the link's
}

// --- the backlog ---------------------------------------------------------------------------------

TEST(MachineSide, TheBacklogIsTheShareOfThePathTheMillHasStillToFollowReportedEveryUpdate) {
  Bench bench;
  bench.start();
  bench.link.complete_moves_at_once = false;  // the mill falls behind: the path piles up
  int last = 0;
  for (int i = 0; i < 40; ++i) {
    // The share is taken after the update's handoffs are in the path and before the mill's target
    // passes any of them: the path as it was plus the 33 new points (each cycle a step further).
    const std::size_t path_then = bench.machine->path_left() + 33;
    bench.update(Eigen::Vector3d(2.0 * kStepMm, 0.0, 0.0));
    LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Backlog));
    LONGS_EQUAL(100 * path_then / motion::MachinePlanner::kPathCapacity, bench.backlog());
    CHECK(bench.backlog() >= last);
    last = bench.backlog();
  }
  CHECK(last >= 25);
  // The mill catches up: the backlog drains.
  bench.link.complete_moves_at_once = true;
  for (int i = 0; i < 300 && bench.backlog() > 0; ++i) {
    bench.link.complete_moves(2);
    bench.update();
  }
  LONGS_EQUAL(0, bench.backlog());
}

TEST(MachineSide, NoBacklogIsReportedWhileTheEventRingIsHalfFullSoAFaultAlwaysFindsASlot) {
  Bench bench;
  bench.start();
  for (std::size_t i = 0; i < control::MachineEventRing::capacity() / 2; ++i) {
    CHECK(bench.events.push({control::MachineEventKind::Backlog, hal::MachineFault::None, false, 0}));
  }
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  LONGS_EQUAL(control::MachineEventRing::capacity() / 2, bench.seen.size());
  CHECK(!bench.link.moves().empty());  // the update went on
  for (std::size_t i = 0; i + 1 < control::MachineEventRing::capacity() / 2; ++i) {
    CHECK(bench.events.push({control::MachineEventKind::Backlog, hal::MachineFault::None, false, 0}));
  }
  bench.update(Eigen::Vector3d(1e-3, 0.0, 0.0));
  LONGS_EQUAL(control::MachineEventRing::capacity() / 2, bench.seen.size());  // one slot to spare: reported
}

TEST(MachineSide, APathThatOverflowsIsAFaultThatStopsTheMill) {
  Bench bench;
  bench.start();
  bench.link.complete_moves_at_once = false;
  int backlog = 0;
  for (int i = 0; i < 200 && bench.machine->state() == control::MachineSideState::Cutting; ++i) {
    bench.update(Eigen::Vector3d(2.0 * kStepMm, 0.0, 0.0));
    backlog = bench.backlog() >= 0 ? bench.backlog() : backlog;
  }
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  CHECK(backlog >= 95);  // the cycle was told, update after update, before it came to this
  LONGS_EQUAL(1, bench.seen_count(control::MachineEventKind::Fault));
  LONGS_EQUAL(1, bench.link.stops());
}

// --- the reversal deadband -----------------------------------------------------------------------

// The virtual tool trembles against a wall as the hand slides along it: a step or two back is not
// worth a backlash take-up, so the mill holds that axis while it follows the others; a real
// reversal is followed, its backlash taken up first.
TEST(MachineSide, ATrembleWithinTheDeadbandCostsNoTakeUpAndARealReversalTakesUpTheBacklash) {
  Bench bench;
  bench.start();
  for (int i = 0; i < 5; ++i) {
    bench.update(Eigen::Vector3d(1e-3, 1e-3, 0.0));  // +x +y: the slack of both on the side they go
  }
  LONGS_EQUAL(0, bench.machine->statistics().take_ups);
  std::int32_t x_steps = bench.link.status().commanded_steps[0];
  bool x_went_back = false;
  for (int i = 0; i < 30; ++i) {
    bench.tip.x() += (i % 2 == 0 ? -2.0 : 2.0) * kStepMm;  // two steps back, then forth again
    bench.update(Eigen::Vector3d(0.0, 1e-3, 0.0));
    // +x in the world is -x for the machine (machine_sign): back is a larger step count.
    x_went_back = x_went_back || bench.link.status().commanded_steps[0] > x_steps;
    x_steps = std::min(x_steps, bench.link.status().commanded_steps[0]);
  }
  CHECK(bench.link.moves().size() > 30);  // it kept following y all along
  LONGS_EQUAL(0, bench.machine->statistics().take_ups);
  CHECK_FALSE(x_went_back);
  bench.tip.x() -= 13.0 * kStepMm;  // thirteen back: a reversal
  for (int i = 0; i < 10; ++i) {
    bench.update(Eigen::Vector3d(0.0, 1e-3, 0.0));
  }
  CHECK(bench.machine->statistics().take_ups >= 1);
  CHECK(bench.link.status().commanded_steps[0] > x_steps + 80);  // the 80 steps of slack, then the move
}

// Found while writing the test above (see the report of issue 26): with the mill standing exactly on
// the virtual tool's step (at its goal) and the tool stepping back 3 steps along one axis only, the
// deadband's "stay where it is" candidate is the mill's own position, which corner_target skips
// (corner == axis_), and every other corner of that cell reverses some axis: the mill takes up the
// backlash for a 3-step retreat. Left ignored: the planner is not this suite's to change.
IGNORE_TEST(MachineSide, AStillMillKeepsItsAxisWhenTheToolStepsBackWithinTheDeadband) {
  Bench bench;
  bench.start();
  for (int i = 0; i < 30; ++i) {
    bench.update(i < 3 ? Eigen::Vector3d(1e-3, 0.0, 0.0) : Eigen::Vector3d::Zero());  // +x, then still
  }
  CHECK_TRUE(bench.machine->at_goal());
  const std::int32_t x_steps = bench.link.status().commanded_steps[0];
  bench.tip.x() -= 3.0 * kStepMm;  // three steps back: inside the deadband
  for (int i = 0; i < 10; ++i) {
    bench.update();
  }
  LONGS_EQUAL(x_steps, bench.link.status().commanded_steps[0]);
  LONGS_EQUAL(0, bench.machine->statistics().take_ups);
}
