// The machine side's record before send (issue 18, item 10): a target goes to the mill only once the
// recorder says it is written; until then the mill holds, update after update, and that is not a
// fault unless it lasts past the bound; a recorder that refuses the target is a journal fault with
// nothing sent.
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

namespace {

// A recorder whose writer is as slow as the test says: command() queues, written() is true once the
// test has let the queued targets through (or at once, like stencil-sim --fast's).
class SlowRecorderSpy final : public control::MachineRecorder {
 public:
  bool refuse = false;
  bool write_at_once = false;
  std::vector<control::MachineCommandRecord> queued;
  std::size_t written_count = 0;

  [[nodiscard]] bool homed(std::int64_t) override { return true; }
  [[nodiscard]] bool command(const control::MachineCommandRecord& record) override {
    if (refuse) {
      return false;
    }
    queued.push_back(record);
    if (write_at_once) {
      written_count = queued.size();
    }
    return true;
  }
  [[nodiscard]] bool written() const override { return written_count == queued.size(); }
  void write_everything() { written_count = queued.size(); }
};

constexpr hal::MonotonicNs kUpdateNs = 33'333'333;

struct Bench {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  control::MachineHandoffRing handoffs;
  control::MachineEventRing events;
  test::SpyMachineLink link;
  SlowRecorderSpy recorder;
  // Home well above the hex prism (its top is at z 6): the tool moves in free air.
  motion::MachineFrames frames{10.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(25.0, 12.5, 20.0), {-1, -1, -1}, 640.0};
  motion::PlannerLimits limits{{1.4, 1000.0, 640.0}, 1.0 / 30.0, {80, 32, 80}};
  std::unique_ptr<control::MachineSide> machine;
  hal::MonotonicNs now = 0;
  std::uint64_t cycle = 0;
  double x_mm = 25.0;
  bool paused = false;  // the cycle's feed hold, in every handoff

  Bench() {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    machine = std::make_unique<control::MachineSide>(part, link, frames, limits, handoffs, events);
    machine->record_to(&recorder);
    CHECK_TRUE(machine->start(1'000'000'000));
  }
  // One machine update's worth of cycles: the virtual tool moves +x at 1 mm/s, then the update.
  void update() {
    for (int i = 0; i < 33; ++i) {
      x_mm += paused ? 0.0 : 1e-3;  // paused, the virtual tool stays
      CHECK(handoffs.push({++cycle, {x_mm, 12.5, 20.0}, false, paused}));
    }
    now += kUpdateNs;
    machine->update(now + 2 * kUpdateNs);
  }
  [[nodiscard]] bool event_seen(control::MachineEventKind kind) {
    control::MachineEvent event{};
    bool seen = false;
    while (events.pop(event)) {
      seen = seen || event.kind == kind;
    }
    return seen;
  }
};

}  // namespace

TEST_GROUP(MachineSideRecording){};

TEST(MachineSideRecording, ATargetGoesToTheMillOnlyOnceTheRecordHasItAndTheMillHoldsUntilThen) {
  Bench bench;
  // At every move the record must already hold the target moved to, written, in its place.
  int sent_unwritten = 0;
  bench.link.on_move = [&](const hal::MachineTarget& target) {
    const std::size_t place = bench.link.moves().size();
    const auto& queued = bench.recorder.queued;
    const bool in_record = place < bench.recorder.written_count && queued[place].motor_target[0] == target.motor_steps[0] &&
                           queued[place].motor_target[1] == target.motor_steps[1] &&
                           queued[place].motor_target[2] == target.motor_steps[2];
    sent_unwritten += in_record ? 0 : 1;
  };
  bench.update();
  LONGS_EQUAL(1, bench.recorder.queued.size());  // planned and queued for the record ...
  LONGS_EQUAL(0, bench.link.moves().size());      // ... not sent
  for (int held = 1; held <= 5; ++held) {         // the disk stalls for five updates
    bench.update();
    LONGS_EQUAL(1, bench.recorder.queued.size());
    LONGS_EQUAL(0, bench.link.moves().size());
    LONGS_EQUAL(held, bench.machine->statistics().held_for_record);
  }
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);  // held, not a fault
  CHECK_FALSE(bench.event_seen(control::MachineEventKind::JournalFailed));
  bench.recorder.write_everything();
  bench.update();  // the next target is planned and queued, then the held one sent
  LONGS_EQUAL(1, bench.link.moves().size());
  LONGS_EQUAL(2, bench.recorder.queued.size());
  LONGS_EQUAL(1, bench.machine->statistics().updates);
  // A writer that keeps up: one target a update, each sent the update after it was queued.
  for (int i = 0; i < 20; ++i) {
    bench.recorder.write_everything();
    bench.update();
  }
  LONGS_EQUAL(21, bench.link.moves().size());
  LONGS_EQUAL(22, bench.recorder.queued.size());
  LONGS_EQUAL(0, sent_unwritten);
  for (std::size_t i = 0; i < bench.link.moves().size(); ++i) {  // sent in the order recorded
    LONGS_EQUAL(bench.recorder.queued[i].motor_target[0], bench.link.moves()[i].motor_steps[0]);
    LONGS_EQUAL(i, bench.recorder.queued[i].update);
  }
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);
}

TEST(MachineSideRecording, ATargetThatStaysUnwrittenPastTheBoundIsAJournalFaultWithNothingSent) {
  Bench bench;
  bench.update();
  for (int i = 0; i < control::MachineSide::kMaxUnrecordedUpdates; ++i) {
    bench.update();
  }
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);  // at the bound: still holding
  bench.update();
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  CHECK_TRUE(bench.machine->record_failed());
  CHECK_TRUE(bench.event_seen(control::MachineEventKind::JournalFailed));
  LONGS_EQUAL(0, bench.link.moves().size());
  LONGS_EQUAL(1, bench.link.stops());
}

TEST(MachineSideRecording, ARecorderThatWritesAtOnceHasTheTargetSentInTheSameUpdate) {
  Bench bench;
  bench.recorder.write_at_once = true;
  for (int i = 1; i <= 10; ++i) {
    bench.update();
    LONGS_EQUAL(i, bench.link.moves().size());
    LONGS_EQUAL(i, bench.recorder.queued.size());
  }
  LONGS_EQUAL(0, bench.machine->statistics().held_for_record);
}

TEST(MachineSideRecording, ARefusedRecordIsAJournalFaultAndTheTargetIsNotSent) {
  Bench bench;
  bench.recorder.refuse = true;
  bench.update();
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  CHECK_TRUE(bench.machine->record_failed());
  CHECK_TRUE(bench.event_seen(control::MachineEventKind::JournalFailed));
  LONGS_EQUAL(0, bench.link.moves().size());
}

// One target an update, as ever: in the update that sends a held target, the next one waits for the
// next update even if the record has it written at once (the records thread, woken by the target,
// may run between command() and written()); two moves in one update outlast the update's deadline
// on the CY545 (found in stencil-sim --speed 1: DeadlineTooShort, machine_fault).
TEST(MachineSideRecording, AfterAHeldTargetGoesTheNextWaitsForTheNextUpdateEvenIfAlreadyWritten) {
  Bench bench;
  bench.update();  // queued, held
  LONGS_EQUAL(0, bench.link.moves().size());
  bench.recorder.write_everything();
  bench.recorder.write_at_once = true;  // from here every target is written the moment it is queued
  bench.update();                       // the held one goes; the next is planned, written, and waits
  LONGS_EQUAL(1, bench.link.moves().size());
  LONGS_EQUAL(2, bench.recorder.queued.size());
  for (int i = 0; i < 10; ++i) {  // from here each update sends the one before and queues the next
    bench.update();
    LONGS_EQUAL(2 + i, bench.link.moves().size());
    LONGS_EQUAL(3 + i, bench.recorder.queued.size());
  }
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);
}

// Issue 22: the operator's Pause holds the feed at the link at the next update; nothing is planned,
// recorded or sent while it lasts (the heartbeat goes on), and Resume carries on with no homing.
TEST(MachineSideRecording, APauseHoldsTheFeedAndSendsNothingUntilTheResume) {
  Bench bench;
  bench.recorder.write_at_once = true;
  for (int i = 0; i < 5; ++i) {
    bench.update();
  }
  const std::size_t moves = bench.link.moves().size();
  const std::size_t records = bench.recorder.queued.size();
  CHECK(moves > 0);
  bench.paused = true;
  const int beats = bench.link.keep_alives();
  for (int i = 0; i < 6; ++i) {
    bench.update();
    CHECK(bench.link.status().state == hal::MachineState::Held);
    CHECK(bench.machine->held());
  }
  LONGS_EQUAL(moves, bench.link.moves().size());
  LONGS_EQUAL(records, bench.recorder.queued.size());
  LONGS_EQUAL(0, bench.link.refused_while_held());
  LONGS_EQUAL(1, bench.machine->statistics().holds);
  LONGS_EQUAL(6, bench.machine->statistics().held_updates);
  LONGS_EQUAL(beats + 6, bench.link.keep_alives());  // the watchdog relay's heartbeat goes on
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);  // held, not stopped
  bench.paused = false;
  for (int i = 0; i < 5; ++i) {
    bench.update();
  }
  CHECK(bench.link.status().state == hal::MachineState::Homed);
  CHECK_FALSE(bench.machine->held());
  CHECK(bench.link.moves().size() > moves);
  LONGS_EQUAL(0, bench.link.refused_while_held());
  LONGS_EQUAL(0, bench.link.stops());
}

TEST(MachineSideRecording, AStopWhileHeldStopsTheMillAndLeavesNoHoldShowing) {
  Bench bench;
  bench.recorder.write_at_once = true;
  bench.update();
  bench.paused = true;
  bench.update();
  CHECK(bench.machine->held());
  CHECK(bench.handoffs.push({++bench.cycle, {bench.x_mm, 12.5, 20.0}, true, false}));  // the safe state ends the pause
  bench.now += kUpdateNs;
  bench.machine->update(bench.now + 2 * kUpdateNs);
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  LONGS_EQUAL(1, bench.link.stops());
  CHECK_FALSE(bench.machine->held());
}
