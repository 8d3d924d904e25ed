// One recorded run replayed (board/sim/journal_replay): each cycle's recorded read handed to the
// device, the commands each recorded cycle took pushed into the cycle's ring in their cycle, a safe
// state the read and the commands do not explain given back as a stop from the replay, the replayed
// virtual tool compared bit for bit with the recorded one (or with its CRC where only that was kept),
// and the run ending with its records. Against a real controller that has not stepped: its virtual
// tool stays where it starts, so a record of that tip matches and any other does not. The whole
// replay of a job: e2e sim_replay_gives_the_recorded_job_back.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "board/sim/journal_replay.hpp"
#include "board/sim/sim_job.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/services/journal/cycle_codec.hpp"
#include "sim/haptic_device/replay_haptic_device.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

struct Bench {
  test::LoadedPart loaded{test::default_part(), 1};
  stencil::sim::ReplayHapticDevice device;
  std::unique_ptr<control::CycleRingStorage> rings = std::make_unique<control::CycleRingStorage>();
  std::unique_ptr<control::Controller> controller =
      std::make_unique<control::Controller>(loaded.part, device, rings->rings(), controller_config(false));
  control::CommandRing commands;

  // A record of cycle `cycle` whose tip is the controller's (`offset_mm` off in x).
  [[nodiscard]] journal::RecordedCycle record(std::uint64_t cycle, double offset_mm = 0.0) const {
    journal::RecordedCycle r;
    r.record.cycle = cycle;
    const Eigen::Vector3d tip = controller->virtual_tip_mm();
    r.record.virtual_tip_mm[0] = tip.x() + offset_mm;
    r.record.virtual_tip_mm[1] = tip.y();
    r.record.virtual_tip_mm[2] = tip.z();
    r.record.safe_reason = control::SafeReason::None;
    r.record.device_mm[0] = 100.0 + static_cast<double>(cycle);
    r.record.read_status = hal::ReadStatus::Fresh;
    return r;
  }
};

control::CommandEvent taken(std::uint64_t cycle, control::CommandKind kind) {
  return {cycle, 0, cycle, kind, control::CommandSource::Display, control::CommandOutcome::Done, 0.0, 0.0};
}

runtime::CycleTime at(double t_s) { return {static_cast<hal::MonotonicNs>(t_s * 1e9), t_s}; }

void run_cycle(JournalReplay& replay, double t_s) {
  replay.after_cycle(at(t_s), control::CycleStatus::Running);
}

}  // namespace

TEST_GROUP(JournalReplay){};

TEST(JournalReplay, EndsWithItsRecordsAndCountsEveryCycle) {
  Bench b;
  const std::vector<journal::RecordedCycle> records{b.record(0), b.record(1)};
  const std::vector<control::CommandEvent> none;
  JournalReplay replay(records, none, b.device, *b.controller, b.commands);
  CHECK_TRUE(replay.before_cycle(at(0.0)));
  run_cycle(replay, 0.0);
  CHECK_TRUE(replay.before_cycle(at(0.001)));
  run_cycle(replay, 0.001);
  CHECK_FALSE(replay.before_cycle(at(0.002)));
  CHECK_EQUAL(2U, replay.cycles());
  CHECK_EQUAL(0U, replay.mismatches());
  CHECK_EQUAL(-1, replay.first_mismatch());
}

TEST(JournalReplay, TheDeviceGivesTheRecordedRead) {
  Bench b;
  const std::vector<journal::RecordedCycle> records{b.record(7)};
  const std::vector<control::CommandEvent> none;
  JournalReplay replay(records, none, b.device, *b.controller, b.commands);
  CHECK_TRUE(replay.before_cycle(at(0.0)));
  hal::HapticSample sample{};
  CHECK(b.device.read_sample(0, sample).status == hal::ReadStatus::Fresh);
  DOUBLES_EQUAL(107.0, sample.position_mm[0], 0.0);
}

TEST(JournalReplay, ATipThatDiffersIsFoundAtItsFirstCycle) {
  Bench b;
  const std::vector<journal::RecordedCycle> records{b.record(10), b.record(11, 1e-9), b.record(12, 0.5)};
  const std::vector<control::CommandEvent> none;
  JournalReplay replay(records, none, b.device, *b.controller, b.commands);
  for (int i = 0; i < 3; ++i) {
    CHECK_TRUE(replay.before_cycle(at(0.001 * i)));
    run_cycle(replay, 0.001 * i);
  }
  CHECK_EQUAL(2U, replay.mismatches());
  CHECK_EQUAL(11, replay.first_mismatch());
}

TEST(JournalReplay, WhereOnlyTheCrcWasKeptItStandsForTheTip) {
  Bench b;
  journal::RecordedCycle same = b.record(0);
  same.tool_recorded = false;
  same.tip_check = journal::tip_check(same.record.virtual_tip_mm);
  journal::RecordedCycle other = same;
  other.record.cycle = 1;
  other.tip_check ^= 1U;
  const std::vector<journal::RecordedCycle> records{same, other};
  const std::vector<control::CommandEvent> none;
  JournalReplay replay(records, none, b.device, *b.controller, b.commands);
  for (int i = 0; i < 2; ++i) {
    CHECK_TRUE(replay.before_cycle(at(0.001 * i)));
    run_cycle(replay, 0.001 * i);
  }
  CHECK_EQUAL(1U, replay.mismatches());
  CHECK_EQUAL(1, replay.first_mismatch());
}

TEST(JournalReplay, EachCommandIsGivenInTheCycleThatTookIt) {
  Bench b;
  const std::vector<journal::RecordedCycle> records{b.record(5), b.record(6), b.record(7)};
  const std::vector<control::CommandEvent> commands{taken(3, control::CommandKind::Pause),
                                                    taken(6, control::CommandKind::Resume),
                                                    taken(6, control::CommandKind::Stop)};
  JournalReplay replay(records, commands, b.device, *b.controller, b.commands);
  // Cycle 5: the pause taken before the first record, at once.
  CHECK_TRUE(replay.before_cycle(at(0.0)));
  CHECK_EQUAL(1U, b.commands.size());
  control::Command command{control::CommandKind::Reset, 0.0, control::CommandSource::Program, 0};
  CHECK_TRUE(b.commands.pop(command));
  CHECK(command.kind == control::CommandKind::Pause);
  CHECK(command.source == control::CommandSource::Display);  // as it came
  run_cycle(replay, 0.0);
  CHECK_TRUE(replay.before_cycle(at(0.001)));
  CHECK_EQUAL(2U, b.commands.size());
  CHECK_TRUE(b.commands.pop(command));
  CHECK(command.kind == control::CommandKind::Resume);
  CHECK_TRUE(b.commands.pop(command));
  CHECK(command.kind == control::CommandKind::Stop);
  run_cycle(replay, 0.001);
  CHECK_TRUE(replay.before_cycle(at(0.002)));
  CHECK_EQUAL(0U, b.commands.size());
  CHECK_EQUAL(0U, replay.commands_not_replayed());
}

TEST(JournalReplay, ASafeStateNothingExplainsIsGivenBackAsTheReplaysStop) {
  Bench b;
  journal::RecordedCycle machine_fault = b.record(0);
  machine_fault.record.safe_reason = control::SafeReason::MachineFault;
  journal::RecordedCycle device_reason = b.record(1);
  device_reason.record.safe_reason = control::SafeReason::PoseJump;  // the device's read explains it
  const std::vector<journal::RecordedCycle> records{machine_fault, device_reason};
  const std::vector<control::CommandEvent> none;
  JournalReplay replay(records, none, b.device, *b.controller, b.commands);
  CHECK_TRUE(replay.before_cycle(at(0.0)));
  control::Command command{control::CommandKind::Reset, 0.0, control::CommandSource::Program, 0};
  CHECK_TRUE(b.commands.pop(command));
  CHECK(command.kind == control::CommandKind::Stop);
  CHECK(command.source == control::CommandSource::Replay);
  run_cycle(replay, 0.0);
  CHECK(replay.recorded_reason() == control::SafeReason::MachineFault);
  CHECK_TRUE(replay.before_cycle(at(0.001)));
  CHECK_EQUAL(0U, b.commands.size());
}

TEST(JournalReplay, CommandsBeyondWhatTheRingHoldsAreCounted) {
  Bench b;
  const std::vector<journal::RecordedCycle> records{b.record(0)};
  std::vector<control::CommandEvent> many;
  for (std::size_t i = 0; i < control::CommandRing::capacity() + 3; ++i) {
    many.push_back(taken(0, control::CommandKind::Pause));
  }
  JournalReplay replay(records, many, b.device, *b.controller, b.commands);
  CHECK_TRUE(replay.before_cycle(at(0.0)));
  CHECK(replay.commands_not_replayed() >= 3U);
}
