// The cycle against a scripted device and the real engine on the hex prism: following, force, and
// every trigger of the safe state (zero force in the same period, the machine told to stop, the
// reason latched), the reset rule and the ramp.
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "firmware/core/control/controller.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/fakes/fake_haptic_device.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::control;

namespace {

constexpr hal::MonotonicNs kPeriodNs = 1'000'000;
const Eigen::Vector3d kHomeWorld(25.0, 12.5, 20.0);  // above the prism (top at z = 6)
const Eigen::Vector3d kHomeDevice = 10.0 * kHomeWorld;

// The hex prism's tables, made per test (so that CppUTest's leak check sees them freed).
struct Prism {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  Prism() { CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok); }
};

ControllerConfig config() {
  ControllerConfig c;
  c.frames = {10.0, Eigen::Vector3d::Zero(), kHomeWorld, {-1, -1, 1}, 640.0};
  c.device_low_mm = Eigen::Vector3d(-25.0, -25.0, -25.0);
  c.device_high_mm = Eigen::Vector3d(525.0, 275.0, 275.0);
  c.home_tip_mm = kHomeWorld;
  return c;
}

// The controller with its rings and a scripted device; one cycle per call, 1 ms apart.
struct Bench {
  Prism prism;
  test::FakeHapticDevice device;
  CommandRing commands;
  MachineEventRing machine_events;
  MachineHandoffRing machine;
  TelemetryRing telemetry;
  JournalRing journal;
  CommandEventRing command_events;
  CommandRing display_commands;
  std::vector<CommandEvent> events;  // every command the cycle took, in order
  std::vector<JournalRecord> records;
  bool keep_records = false;
  std::unique_ptr<Controller> controller;
  hal::MonotonicNs now = 1'000'000'000;
  MachineHandoff last_handoff{};
  Telemetry last_telemetry{};
  bool drain_machine = true;
  bool drain_journal = true;
  hal::MonotonicNs compute_ns = 100'000;  // how long each step "takes"

  explicit Bench(const ControllerConfig& c = config()) {
    device.hold_at(kHomeDevice.x(), kHomeDevice.y(), kHomeDevice.z());
    controller = std::make_unique<Controller>(prism.part, device, CycleRings{commands, machine_events, machine, telemetry, journal, command_events, &display_commands}, c);
    CHECK(controller->ready());
  }

  CycleStatus cycle() {
    const CycleStatus status = controller->step(now, now);
    controller->finish(now + compute_ns, now + kPeriodNs);
    now += kPeriodNs;
    MachineHandoff handoff{};
    while (drain_machine && machine.pop(handoff)) {
      last_handoff = handoff;
    }
    JournalRecord record{};
    while (drain_journal && journal.pop(record)) {
      if (keep_records) {
        records.push_back(record);
      }
    }
    CommandEvent event{};
    while (command_events.pop(event)) {
      events.push_back(event);
    }
    Telemetry t{};
    while (telemetry.pop(t)) {
      last_telemetry = t;
    }
    return status;
  }

  void cycles(int n) {
    for (int i = 0; i < n; ++i) {
      static_cast<void>(cycle());
    }
  }

  // Moves the device in a straight line to `to` at `speed` (device mm per second), one sample a cycle.
  void move_device_to(const Eigen::Vector3d& to, double speed_mm_per_s) {
    Eigen::Vector3d at(device_position());
    const double step = speed_mm_per_s * 1e-3;
    while ((to - at).norm() > step) {
      at += step * (to - at).normalized();
      device.hold_at(at.x(), at.y(), at.z());
      static_cast<void>(cycle());
    }
    device.hold_at(to.x(), to.y(), to.z());
    static_cast<void>(cycle());
  }

  [[nodiscard]] Eigen::Vector3d device_position() const {
    return {last_telemetry.device_mm[0], last_telemetry.device_mm[1], last_telemetry.device_mm[2]};
  }

  [[nodiscard]] double force_written() const {
    const hal::HapticCommand& c = device.last_command();
    return std::sqrt(c.force_n[0] * c.force_n[0] + c.force_n[1] * c.force_n[1] + c.force_n[2] * c.force_n[2]);
  }
};

// The outcome every trigger must have, in the very cycle that saw it.
void check_safe(const Bench& bench, SafeReason reason) {
  CHECK_TEXT(bench.controller->safe_reason() == reason, safe_reason_name(bench.controller->safe_reason()));
  const hal::HapticCommand& command = bench.device.last_command();
  CHECK_FALSE(command.enable);
  DOUBLES_EQUAL(0.0, bench.force_written(), 0.0);
  DOUBLES_EQUAL(0.0, command.torque_nmm[0], 0.0);
  DOUBLES_EQUAL(0.0, command.torque_nmm[1], 0.0);
  CHECK(bench.last_handoff.safe_state);  // the machine side is told to hold and stop
  CHECK(bench.last_telemetry.safe_reason == reason);
}

}  // namespace

TEST_GROUP(Controller){};

TEST(Controller, FollowsTheDeviceInFreeSpaceWithNoForce) {
  Bench bench;
  bench.cycles(5);
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(30.0, -20.0, 10.0), 500.0);
  CHECK(bench.cycle() == CycleStatus::Running);
  const Eigen::Vector3d tip = bench.controller->virtual_tip_mm();
  CHECK((tip - (kHomeWorld + Eigen::Vector3d(3.0, -2.0, 1.0))).norm() < 1e-9);
  DOUBLES_EQUAL(0.0, bench.force_written(), 1e-9);
  CHECK(bench.device.last_command().enable);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  CHECK(bench.last_handoff.virtual_tip_mm[0] == tip.x());
  CHECK_FALSE(bench.last_handoff.safe_state);
}

TEST(Controller, PushedIntoThePartTheToolStaysOnTheSurfaceAndTheOperatorFeelsIt) {
  Bench bench;
  bench.cycles(600);  // past the start-up ramp
  // Down onto the top face (z = 6 world) and 0.2 mm (2 device mm) into it.
  bench.move_device_to({250.0, 125.0, 58.0}, 1000.0);
  bench.cycles(10);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  const Eigen::Vector3d tip = bench.controller->virtual_tip_mm();
  CHECK(tip.z() >= 6.0 - bench.prism.part.header.gouge_bound_mm - 1e-6);
  CHECK(tip.z() < 6.01);
  const hal::HapticCommand& command = bench.device.last_command();
  CHECK(command.force_n[2] > 1.0);  // pushing the hand back up
  CHECK(bench.force_written() <= 5.0 + 1e-12);
  CHECK(bench.controller->touched().count() > 0);  // the top's triangles, touched by the virtual tool
}

// The wall's virtual damper (issue 29): a hand moving into the face is pushed back harder while it
// moves, and by the same force once it rests.
TEST(Controller, WithTheWallsDamperAHandMovingIntoTheFaceIsPushedBackHarderWhileItMoves) {
  ControllerConfig damped = config();
  damped.feel.damping_n_s_per_m = 20.0;
  Bench plain;
  Bench with_damper(damped);
  for (Bench* bench : {&plain, &with_damper}) {
    bench->cycles(600);
    bench->move_device_to({250.0, 125.0, 61.0}, 1000.0);  // just above the top face (z = 6 world)
    bench->move_device_to({250.0, 125.0, 58.5}, 100.0);  // 1.5 device mm into it at 100 device mm/s
  }
  // Moving in at 0.1 m/s: the damper adds about 20 N s/m x 0.1 m/s = 2 N, less its filter's lag.
  const double moving_extra = with_damper.device.last_command().force_n[2] - plain.device.last_command().force_n[2];
  CHECK(moving_extra > 1.0);
  CHECK(moving_extra < 2.0 + 1e-9);
  plain.cycles(200);
  with_damper.cycles(200);
  DOUBLES_EQUAL(plain.device.last_command().force_n[2], with_damper.device.last_command().force_n[2], 1e-3);
}

// Friction (issue 29): pressed onto the top face and pulled sideways less than the cone holds, the
// virtual tool stays; with none (today's rendering) it slips along under the hand.
TEST(Controller, WithFrictionAToolPressedOnTheFaceStaysWhenPulledSidewaysInsideTheCone) {
  ControllerConfig rough = config();
  rough.feel.friction = 1.0;
  Bench plain;
  Bench with_friction(rough);
  for (Bench* bench : {&plain, &with_friction}) {
    bench->cycles(600);
    bench->move_device_to({250.0, 125.0, 61.0}, 1000.0);
    bench->move_device_to({250.0, 125.0, 56.0}, 100.0);  // 4 device mm past the face: about 3 N of push
    bench->cycles(20);
  }
  const Eigen::Vector3d plain_before = plain.controller->virtual_tip_mm();
  const Eigen::Vector3d rough_before = with_friction.controller->virtual_tip_mm();
  for (Bench* bench : {&plain, &with_friction}) {
    bench->move_device_to({252.0, 125.0, 56.0}, 20.0);  // 2 device mm along: 1 N of pull at 0.5 N/mm
    bench->cycles(20);
  }
  CHECK(with_friction.controller->safe_reason() == SafeReason::None);
  DOUBLES_EQUAL(rough_before.x(), with_friction.controller->virtual_tip_mm().x(), 1e-9);
  CHECK(plain.controller->virtual_tip_mm().x() - plain_before.x() > 0.15);  // followed the hand, 0.2 mm world
  CHECK(with_friction.device.last_command().force_n[0] < -0.5);  // the hand feels the hold
}

// Penalty-based speed limiting (issue 29): with the mill's speed cap on (1 world mm/s, 10 device
// mm/s), a hand moving in free space at 8 device mm/s feels a force against it with the penalty, and
// nothing with the cap alone (the virtual tool keeps up with it).
TEST(Controller, WithTheSpeedPenaltyAHandNearTheMillsSpeedIsHeldBackAndWithTheCapAloneItIsNot) {
  ControllerConfig capped = config();
  capped.max_axis_move_mm = 1e-3;
  capped.max_total_move_mm = 1e-3;
  ControllerConfig penalised = capped;
  penalised.feel.speed_limiting = engine::SpeedLimiting::Penalty;
  Bench cap(capped);
  Bench penalty(penalised);
  for (Bench* bench : {&cap, &penalty}) {
    bench->cycles(600);  // past the start-up ramp
    bench->move_device_to(kHomeDevice + Eigen::Vector3d(2.4, 0.0, 0.0), 8.0);  // 300 periods at 8 mm/s
  }
  DOUBLES_EQUAL(0.0, cap.force_written(), 1e-9);
  // 350 N s/m past a tenth of the limit: 350 x (8 - 1) mm/s = 2.45 N, against the motion.
  const hal::HapticCommand& held = penalty.device.last_command();
  DOUBLES_EQUAL(-2.45, held.force_n[0], 0.05);
  DOUBLES_EQUAL(0.0, held.force_n[1], 1e-9);
  DOUBLES_EQUAL(0.0, held.force_n[2], 1e-9);
  CHECK(penalty.controller->safe_reason() == SafeReason::None);
}

TEST(Controller, TheSpeedPenaltyLeavesSlowMotionAloneAndTheCapStillBoundsTheTool) {
  ControllerConfig penalised = config();
  penalised.max_axis_move_mm = 1e-3;
  penalised.max_total_move_mm = 1e-3;
  penalised.feel.speed_limiting = engine::SpeedLimiting::Penalty;
  Bench bench(penalised);
  bench.cycles(600);
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(0.0, 0.16, 0.0), 0.8);  // under a tenth of 10 mm/s
  DOUBLES_EQUAL(0.0, bench.force_written(), 1e-9);
  // A hand far faster than the mill: the penalty at the force limit, and the tool no faster than the cap.
  const Eigen::Vector3d before = bench.controller->virtual_tip_mm();
  bench.move_device_to(bench.device_position() + Eigen::Vector3d(0.0, 10.0, 0.0), 100.0);
  CHECK((bench.controller->virtual_tip_mm() - before).cwiseAbs().sum() <= 101 * 1e-3 + 1e-12);
  DOUBLES_EQUAL(5.0, bench.force_written(), 1e-9);
}

TEST(Controller, AStaleDeviceForMoreThanFivePeriodsEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.give(hal::ReadStatus::Stale);
  for (int i = 0; i < 5; ++i) {
    CHECK(bench.cycle() == CycleStatus::Running);
  }
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::DeviceStale);
}

TEST(Controller, ANonFinitePoseEntersTheSafeStateInThatPeriod) {
  Bench bench;
  bench.cycles(20);
  bench.device.hold_at(std::numeric_limits<double>::quiet_NaN(), 125.0, 200.0);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::PoseNotFinite);
}

TEST(Controller, APoseOutsideTheReachEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.move_device_to({250.0, 125.0, 273.0}, 1000.0);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  bench.device.hold_at(250.0, 125.0, 276.0);  // 1 mm beyond the margin, 3 mm in a period: not a jump
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::PoseOutOfWorkspace);
}

TEST(Controller, ASampleTheBackendRefusedAsOutOfRangeEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.give(hal::ReadStatus::Rejected, hal::HapticFault::SampleOutOfRange);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::PoseOutOfWorkspace);
}

TEST(Controller, AJumpFartherThanAHandCanMoveInOnePeriodEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.hold_at(kHomeDevice.x() + 2.9, kHomeDevice.y(), kHomeDevice.z());  // 2.9 m/s: a hand
  CHECK(bench.cycle() == CycleStatus::Running);
  bench.device.hold_at(kHomeDevice.x() + 2.9 + 3.2, kHomeDevice.y(), kHomeDevice.z());  // 3.2 m/s: not
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::PoseJump);
}

TEST(Controller, ADeviceLinkFaultEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.give(hal::ReadStatus::Fault, hal::HapticFault::DeviceHeartbeatLost);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::DeviceFault);
}

TEST(Controller, AForceWriteThatFailsEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.fail_writes(true);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  CHECK(bench.controller->safe_reason() == SafeReason::DeviceFault);
  CHECK(bench.last_handoff.safe_state);
}

TEST(Controller, AMachineFaultEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.machine_events.push({.kind = MachineEventKind::Fault, .fault = hal::MachineFault::Timeout}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::MachineFault);
}

// The machine side's journal failed (a target it could not write within the bound): nothing after
// it would be recorded, so the run ends there and no reset brings the cycle back.
TEST(Controller, AJournalFailureTheMachineSideReportsEntersTheSafeStateForGood) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.machine_events.push({.kind = MachineEventKind::JournalFailed}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::JournalFailed);
  CHECK(bench.controller->safe_source() == CommandSource::Machine);
  bench.cycles(600);  // the hand held still near the tool: a reset would be taken after any other fault
  CHECK(bench.display_commands.push({CommandKind::Reset, 0.0, CommandSource::Display}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  CHECK(bench.events.back().outcome == CommandOutcome::RunEnding);
  LONGS_EQUAL(0, bench.controller->counters().resets_accepted);
}

// The engine cannot give a force (here the force limit is not a number): zero force in that very
// cycle, the reason the engine's.
TEST(Controller, AForceTheEngineCannotComputeEntersTheSafeStateAsAnEngineFault) {
  ControllerConfig c = config();
  c.haptic.max_force_n = std::numeric_limits<double>::quiet_NaN();
  Bench bench(c);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::EngineFault);
}

TEST(Controller, AMachineSideThatFallsAWholeRingBehindEntersTheSafeState) {
  Bench bench;
  bench.drain_machine = false;
  for (std::size_t i = 0; i < MachineHandoffRing::capacity(); ++i) {
    CHECK(bench.cycle() == CycleStatus::Running);
  }
  CHECK(bench.cycle() == CycleStatus::SafeState);
  CHECK(bench.controller->safe_reason() == SafeReason::MachineFault);
  DOUBLES_EQUAL(0.0, bench.force_written(), 0.0);
  CHECK_FALSE(bench.device.last_command().enable);
}

TEST(Controller, MoreThanThreeOverrunsInARowEnterTheSafeStateButThreeDoNot) {
  Bench bench;
  bench.cycles(20);
  bench.compute_ns = kPeriodNs + 1;  // each step ends after the next deadline
  bench.cycles(3);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  bench.compute_ns = 100'000;
  bench.cycles(1);  // on time: the run of overruns ends
  bench.compute_ns = kPeriodNs + 1;
  bench.cycles(3);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  LONGS_EQUAL(6, bench.controller->statistics().overruns);
  static_cast<void>(bench.controller->step(bench.now, bench.now));
  bench.controller->finish(bench.now + bench.compute_ns, bench.now + kPeriodNs);  // the fourth in a row
  CHECK(bench.controller->safe_reason() == SafeReason::OverrunStorm);
  DOUBLES_EQUAL(0.0, bench.force_written(), 0.0);  // written at once, not a period later
  CHECK_FALSE(bench.device.last_command().enable);
}

TEST(Controller, AStallThatSkipsPeriodsIsOneOverrunAndTheSkippedPeriodsAreCounted) {
  Bench bench;
  bench.cycles(20);
  // The host stalls the cycle for 4.5 ms: the step due at `now` starts 4.5 ms late; the runner
  // skips the three periods that went by whole and runs the one under way (due at +4 ms) at once.
  for (int stall = 0; stall < 5; ++stall) {
    const hal::MonotonicNs due = bench.now;
    static_cast<void>(bench.controller->step(due + 4'500'000, due));
    bench.controller->finish(due + 4'600'000, due + kPeriodNs);
    static_cast<void>(bench.controller->step(due + 4'600'000, due + 4 * kPeriodNs));  // late, not overrun
    bench.controller->finish(due + 4'700'000, due + 5 * kPeriodNs);
    bench.now = due + 5 * kPeriodNs;
    bench.cycles(2);  // on time again
  }
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  LONGS_EQUAL(5, bench.controller->statistics().overruns);
  LONGS_EQUAL(15, bench.controller->statistics().missed_periods);
  CHECK(bench.controller->statistics().wakeup_latency.max_ns() >= 4'500'000);
}

TEST(Controller, OnAVirtualClockOverrunsAreNotCounted) {
  ControllerConfig c = config();
  c.count_overruns = false;
  Bench bench(c);
  bench.compute_ns = 10 * kPeriodNs;
  bench.cycles(20);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  LONGS_EQUAL(0, bench.controller->statistics().overruns);
}

TEST(Controller, AFullJournalRingEntersTheSafeStateForTheJournalMustLoseNothing) {
  Bench bench;
  bench.drain_journal = false;
  for (std::size_t i = 0; i < JournalRing::capacity(); ++i) {
    CHECK(bench.cycle() == CycleStatus::Running);
  }
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::JournalFull);
}

TEST(Controller, AFullTelemetryRingOnlyDropsAndCounts) {
  Bench bench;
  TelemetryRing& ring = bench.telemetry;
  for (std::size_t i = 0; i < TelemetryRing::capacity(); ++i) {
    CHECK(ring.push({}));
  }
  static_cast<void>(bench.controller->step(bench.now, bench.now));
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  LONGS_EQUAL(1, bench.controller->counters().telemetry_dropped);
}

TEST(Controller, AStopCommandEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.commands.push({CommandKind::Stop}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::Stopped);
}

TEST(Controller, AStopFromTheDisplayIsTakenByTheNextCycleAndRecordedWithItsSource) {
  Bench bench;
  bench.keep_records = true;
  bench.cycles(20);
  CHECK(bench.display_commands.push({CommandKind::Stop, 0.0, CommandSource::Display}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::Stopped);
  CHECK(bench.controller->safe_source() == CommandSource::Display);
  LONGS_EQUAL(1, bench.events.size());
  const CommandEvent& stop = bench.events[0];
  CHECK(stop.kind == CommandKind::Stop);
  CHECK(stop.source == CommandSource::Display);
  CHECK(stop.outcome == CommandOutcome::Done);
  LONGS_EQUAL(21, stop.cycle);
  LONGS_EQUAL(20, stop.queued_after_cycle);  // queued between cycles 20 and 21: one cycle's wait
  const JournalRecord& record = bench.records.back();
  CHECK(record.safe_reason == SafeReason::Stopped);
  CHECK(record.safe_source == CommandSource::Display);
  LONGS_EQUAL(21, record.cycle);
  // A second stop finds the safe state latched, and says so.
  CHECK(bench.commands.push({CommandKind::Stop, 0.0, CommandSource::Signal}));
  bench.cycles(1);
  CHECK(bench.events.back().outcome == CommandOutcome::AlreadySafe);
  CHECK(bench.controller->safe_source() == CommandSource::Display);
}

TEST(Controller, APauseHoldsTheVirtualToolAndTheMillAndAResumeCarriesOnWithoutAReset) {
  Bench bench;
  bench.keep_records = true;
  bench.cycles(20);
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(20.0, 0.0, 0.0), 100.0);
  CHECK(bench.display_commands.push({CommandKind::Pause, 0.0, CommandSource::Display}));
  bench.cycles(1);
  CHECK(bench.controller->paused());
  CHECK(bench.last_handoff.paused);
  CHECK(bench.last_telemetry.paused);
  const Eigen::Vector3d held = bench.controller->virtual_tip_mm();
  // The hand moves on; the tool stays, and the hand feels it pulled back towards it.
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(30.0, 0.0, 0.0), 100.0);
  CHECK(bench.controller->virtual_tip_mm() == held);
  CHECK(bench.force_written() > 0.5);
  CHECK(bench.device.last_command().force_n[0] < 0.0);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  CHECK(bench.records.back().paused);
  // A second pause says so; a resume carries on with no reset and no safe state.
  CHECK(bench.display_commands.push({CommandKind::Pause, 0.0, CommandSource::Display}));
  bench.cycles(1);
  CHECK(bench.events.back().outcome == CommandOutcome::AlreadyPaused);
  CHECK(bench.display_commands.push({CommandKind::Resume, 0.0, CommandSource::Display}));
  bench.cycles(100);
  CHECK_FALSE(bench.controller->paused());
  CHECK_FALSE(bench.last_handoff.paused);
  CHECK(bench.controller->virtual_tip_mm().x() > held.x());
  CHECK(bench.controller->safe_reason() == SafeReason::None);
  LONGS_EQUAL(0, bench.controller->counters().resets_accepted);
  CHECK(bench.events.back().kind == CommandKind::Resume);
  CHECK(bench.events.back().outcome == CommandOutcome::Done);
  CHECK(bench.display_commands.push({CommandKind::Resume, 0.0, CommandSource::Display}));
  bench.cycles(1);
  CHECK(bench.events.back().outcome == CommandOutcome::NotPaused);
}

TEST(Controller, AStopEndsAPauseAndAPauseInTheSafeStateIsRefused) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.commands.push({CommandKind::Pause, 0.0, CommandSource::Terminal}));
  bench.cycles(1);
  CHECK(bench.controller->paused());
  CHECK(bench.commands.push({CommandKind::Stop, 0.0, CommandSource::Terminal}));
  bench.cycles(1);
  CHECK_FALSE(bench.controller->paused());
  CHECK(bench.last_handoff.safe_state);
  CHECK(bench.commands.push({CommandKind::Pause, 0.0, CommandSource::Terminal}));
  bench.cycles(1);
  CHECK(bench.events.back().outcome == CommandOutcome::NotRunning);
  CHECK_FALSE(bench.controller->paused());
}

TEST(Controller, EachParameterChangeIsAnEventWithTheValueAskedAndTheValueApplied) {
  Bench bench;
  bench.cycles(5);
  CHECK(bench.display_commands.push({CommandKind::SetForceLimit, 50.0, CommandSource::Display}));
  CHECK(bench.display_commands.push({CommandKind::SetSpeedLimit, 20.0, CommandSource::Display}));
  CHECK(bench.display_commands.push({CommandKind::SetCoupling, -1.0, CommandSource::Display}));
  bench.cycles(1);
  LONGS_EQUAL(3, bench.events.size());
  CHECK(bench.events[0].outcome == CommandOutcome::Clamped);
  DOUBLES_EQUAL(50.0, bench.events[0].asked, 0.0);
  DOUBLES_EQUAL(config().haptic.max_force_n, bench.events[0].applied, 0.0);  // the board's limit
  CHECK(bench.events[1].outcome == CommandOutcome::Done);
  DOUBLES_EQUAL(20.0, bench.events[1].applied, 1e-9);
  DOUBLES_EQUAL(bench.last_telemetry.speed_limit_mm_per_s, bench.events[1].applied, 0.0);
  CHECK(bench.events[2].outcome == CommandOutcome::Refused);
  DOUBLES_EQUAL(config().haptic.coupling_n_per_device_mm, bench.events[2].applied, 0.0);  // unchanged
  for (const CommandEvent& e : bench.events) {
    LONGS_EQUAL(6, e.cycle);
    CHECK(e.source == CommandSource::Display);
  }
}

TEST(Controller, ACommandTheRecordHasNoRoomForIsNotTakenAndIsAJournalFault) {
  Bench bench;
  bench.cycles(5);
  for (std::size_t i = 0; i < CommandEventRing::capacity(); ++i) {
    CHECK(bench.command_events.push({}));  // nobody drains it
  }
  CHECK(bench.commands.push({CommandKind::SetForceLimit, 3.0, CommandSource::Display}));
  CHECK(bench.commands.push({CommandKind::Pause, 0.0, CommandSource::Display}));
  CHECK(bench.controller->step(bench.now, bench.now) == CycleStatus::SafeState);
  CHECK(bench.controller->safe_reason() == SafeReason::JournalFull);
  DOUBLES_EQUAL(config().haptic.max_force_n, bench.last_telemetry.force_limit_n, 0.0);  // not applied
  CHECK_FALSE(bench.controller->paused());
  LONGS_EQUAL(CommandEventRing::capacity(), bench.command_events.size());
}

// The run's own stop (a signal, the job's end) is final: a display's reset taken in the same cycle,
// or after it, does not bring the cycle back, or the run would go on past its end.
TEST(Controller, AResetAfterTheRunsOwnStopIsRefusedEvenInTheSameCycle) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.display_commands.push({CommandKind::Stop, 0.0, CommandSource::Display}));
  bench.cycles(600);  // in the safe state, the hand still near the tool: a reset would be taken now
  CHECK(bench.commands.push({CommandKind::Stop, 0.0, CommandSource::Signal}));
  CHECK(bench.display_commands.push({CommandKind::Reset, 0.0, CommandSource::Display}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  CHECK(bench.events.back().kind == CommandKind::Reset);
  CHECK(bench.events.back().outcome == CommandOutcome::RunEnding);
  CHECK(bench.controller->safe_source() == CommandSource::Display);  // the first reason and source stay
  LONGS_EQUAL(0, bench.controller->counters().resets_accepted);
}

TEST(Controller, AResetAfterADisplaysStopIsTakenAsAfterAnyOther) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.display_commands.push({CommandKind::Stop, 0.0, CommandSource::Display}));
  bench.cycles(600);
  CHECK(bench.display_commands.push({CommandKind::Reset, 0.0, CommandSource::Display}));
  CHECK(bench.cycle() == CycleStatus::Running);
  CHECK(bench.events.back().outcome == CommandOutcome::Done);
  CHECK(bench.controller->safe_source() == CommandSource::Cycle);
}

TEST(Controller, TheDevicesOwnFaultFlagEntersTheSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.set_status_bits(hal::haptic_status::kForceApplied | hal::haptic_status::kDeviceFault);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::DeviceFault);
}

TEST(Controller, ASampleTheBackendFoundNotFiniteIsThePoseNotFiniteSafeState) {
  Bench bench;
  bench.cycles(20);
  bench.device.give(hal::ReadStatus::Rejected, hal::HapticFault::SampleNotFinite);
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::PoseNotFinite);
}

TEST(Controller, AJournalThatCannotBeWrittenEntersTheSafeStateWithItsOwnReason) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.commands.push({CommandKind::JournalFailed}));
  CHECK(bench.cycle() == CycleStatus::SafeState);
  check_safe(bench, SafeReason::JournalFailed);
  STRCMP_EQUAL("journal_failed", stencil::control::safe_reason_name(bench.controller->safe_reason()));
}

TEST(Controller, TheSafeStateLatchesWhenItsCauseIsGone) {
  Bench bench;
  bench.cycles(20);
  bench.device.hold_at(std::numeric_limits<double>::quiet_NaN(), 125.0, 200.0);
  bench.cycles(1);
  bench.device.hold_at(kHomeDevice.x(), kHomeDevice.y(), kHomeDevice.z());
  for (int i = 0; i < 2000; ++i) {
    CHECK(bench.cycle() == CycleStatus::SafeState);
  }
  check_safe(bench, SafeReason::PoseNotFinite);
}

TEST(Controller, AResetIsRefusedWhileTheDeviceMovesOrIsFarFromTheToolAndTakenWhenItIsHeldStillNearIt) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.commands.push({CommandKind::Stop, 0.0, CommandSource::Terminal}));
  bench.cycles(1);
  // Moving at 10 mm/s: not still.
  for (int i = 0; i < 600; ++i) {
    bench.device.hold_at(kHomeDevice.x() + 0.01 * i, kHomeDevice.y(), kHomeDevice.z());
    bench.cycles(1);
  }
  CHECK(bench.commands.push({CommandKind::Reset}));
  bench.cycles(1);
  CHECK(bench.controller->last_reset() == ResetOutcome::DeviceNotStill);
  CHECK(bench.controller->safe_reason() == SafeReason::Stopped);
  // Still, but 6 mm from the virtual tool (which stayed where the stop found it).
  bench.cycles(600);
  CHECK(bench.commands.push({CommandKind::Reset}));
  bench.cycles(1);
  CHECK(bench.controller->last_reset() == ResetOutcome::DeviceFarFromTool);
  CHECK(bench.controller->safe_reason() == SafeReason::Stopped);
  // Back near it, then held still for 0.5 s.
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(1.0, 0.0, 0.0), 100.0);
  bench.cycles(400);
  CHECK(bench.commands.push({CommandKind::Reset}));
  bench.cycles(1);
  CHECK(bench.controller->last_reset() == ResetOutcome::DeviceNotStill);  // 0.4 s only
  bench.cycles(100);
  CHECK(bench.commands.push({CommandKind::Reset}));
  CHECK(bench.cycle() == CycleStatus::Running);
  CHECK(bench.controller->last_reset() == ResetOutcome::Accepted);
  LONGS_EQUAL(1, bench.controller->counters().resets_accepted);
  LONGS_EQUAL(3, bench.controller->counters().resets_refused);
}

TEST(Controller, AfterAResetTheForceRampsBackInOverHalfASecond) {
  Bench bench;
  bench.cycles(600);
  bench.move_device_to({250.0, 125.0, 58.0}, 1000.0);  // 0.2 mm into the top face
  bench.cycles(10);
  const double full = bench.force_written();
  CHECK(full > 1.0);
  CHECK(bench.commands.push({CommandKind::Stop, 0.0, CommandSource::Terminal}));
  bench.cycles(1);
  DOUBLES_EQUAL(0.0, bench.force_written(), 0.0);
  bench.cycles(600);  // held still, 2 mm from the virtual tool on the surface
  CHECK(bench.commands.push({CommandKind::Reset}));
  bench.cycles(1);
  CHECK(bench.controller->last_reset() == ResetOutcome::Accepted);
  DOUBLES_EQUAL(0.0, bench.force_written(), 1e-12);  // the ramp starts at zero
  bench.cycles(249);
  DOUBLES_EQUAL(0.5 * full, bench.force_written(), 0.01 * full);
  bench.cycles(260);
  DOUBLES_EQUAL(full, bench.force_written(), 1e-9 * full);
}

TEST(Controller, AResetOutsideTheSafeStateIsRefusedAndChangesNothing) {
  Bench bench;
  bench.cycles(20);
  CHECK(bench.commands.push({CommandKind::Reset}));
  CHECK(bench.cycle() == CycleStatus::Running);
  CHECK(bench.controller->last_reset() == ResetOutcome::NotInSafeState);
}

TEST(Controller, AResetWhileTheDeviceLinkIsStillDownIsRefused) {
  Bench bench;
  bench.cycles(20);
  bench.device.give(hal::ReadStatus::Fault, hal::HapticFault::DeviceHeartbeatLost);
  bench.device.connect(false);
  bench.cycles(600);
  CHECK(bench.commands.push({CommandKind::Reset}));
  bench.cycles(1);
  CHECK(bench.controller->last_reset() == ResetOutcome::DeviceNotReady);
  CHECK(bench.controller->safe_reason() == SafeReason::DeviceFault);
}

// The mill's backlog slows the virtual tool: at full speed below half the path, not at all from
// 87 % (the mill catches up instead of the path filling, which would leave a gap in it), nor while
// the machine side reports 100 % for a mill that found no way, and back to full speed once the
// backlog drains.
TEST(Controller, TheMillsBacklogSlowsTheVirtualToolAndAtEightySevenPercentHoldsIt) {
  ControllerConfig c = config();
  c.max_axis_move_mm = 1e-3;
  c.max_total_move_mm = 1e-3;
  Bench bench(c);
  bench.cycles(5);
  const auto moved_in_a_cycle = [&bench](std::uint8_t backlog_percent) {
    CHECK(bench.machine_events.push({.kind = MachineEventKind::Backlog, .backlog_percent = backlog_percent}));
    const Eigen::Vector3d before = bench.controller->virtual_tip_mm();
    CHECK(bench.cycle() == CycleStatus::Running);
    return (bench.controller->virtual_tip_mm() - before).cwiseAbs().sum();
  };
  // The hand drawn well ahead along -x, faster than the tool may follow: it goes at its limit.
  bench.move_device_to(kHomeDevice - Eigen::Vector3d(100.0, 0.0, 0.0), 500.0);
  DOUBLES_EQUAL(1e-3, moved_in_a_cycle(10), 1e-12);
  DOUBLES_EQUAL(1e-3, moved_in_a_cycle(50), 1e-12);
  DOUBLES_EQUAL(12.0 / 37.0 * 1e-3, moved_in_a_cycle(75), 1e-12);
  DOUBLES_EQUAL(1.0 / 37.0 * 1e-3, moved_in_a_cycle(86), 1e-12);
  DOUBLES_EQUAL(0.0, moved_in_a_cycle(87), 0.0);
  DOUBLES_EQUAL(0.0, moved_in_a_cycle(100), 0.0);
  CHECK(bench.controller->safe_reason() == SafeReason::None);  // slowed, not a fault
  DOUBLES_EQUAL(1e-3, moved_in_a_cycle(20), 1e-12);
}

TEST(Controller, AForceLimitAboveTheBoardsIsClampedToItAndOneBelowItHoldsTheForceThere) {
  Bench bench;
  bench.cycles(600);  // past the start's ramp
  CHECK(bench.commands.push({CommandKind::SetForceLimit, 50.0}));
  CHECK(bench.cycle() == CycleStatus::Running);
  DOUBLES_EQUAL(5.0, bench.last_telemetry.force_limit_n, 0.0);
  CHECK(bench.last_telemetry.last_parameter == CommandKind::SetForceLimit);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Clamped);
  // Deep into the prism's top (z = 6): the spring would pull far harder than any limit.
  bench.move_device_to(Eigen::Vector3d(250.0, 125.0, 30.0), 400.0);
  bench.cycles(5);
  DOUBLES_EQUAL(5.0, bench.force_written(), 1e-9);
  CHECK(bench.commands.push({CommandKind::SetForceLimit, 2.0}));
  bench.cycles(2);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Applied);
  DOUBLES_EQUAL(2.0, bench.last_telemetry.force_limit_n, 0.0);
  DOUBLES_EQUAL(2.0, bench.force_written(), 1e-9);
  CHECK_EQUAL(2U, bench.last_telemetry.parameter_requests);
}

TEST(Controller, TheCouplingIsKeptInItsRangeAndANumberThatIsNotOneChangesNothing) {
  Bench bench;
  bench.cycles(2);
  DOUBLES_EQUAL(0.5, bench.last_telemetry.coupling_n_per_device_mm, 0.0);
  CHECK(bench.commands.push({CommandKind::SetCoupling, 0.8}));
  bench.cycles(1);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Applied);
  DOUBLES_EQUAL(0.8, bench.last_telemetry.coupling_n_per_device_mm, 0.0);
  CHECK(bench.commands.push({CommandKind::SetCoupling, 10.0}));
  bench.cycles(1);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Clamped);
  DOUBLES_EQUAL(2.0, bench.last_telemetry.coupling_n_per_device_mm, 0.0);
  CHECK(bench.commands.push({CommandKind::SetCoupling, std::numeric_limits<double>::quiet_NaN()}));
  bench.cycles(1);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Refused);
  DOUBLES_EQUAL(2.0, bench.last_telemetry.coupling_n_per_device_mm, 0.0);
  CHECK(bench.commands.push({CommandKind::SetForceLimit, -1.0}));
  bench.cycles(1);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Refused);
  DOUBLES_EQUAL(5.0, bench.last_telemetry.force_limit_n, 0.0);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
}

TEST(Controller, ASpeedLimitNeverRaisesTheMillsAndALowerOneSlowsTheVirtualTool) {
  ControllerConfig c = config();
  c.max_axis_move_mm = 1e-3;
  c.max_total_move_mm = 1e-3;
  Bench bench(c);
  bench.cycles(5);
  DOUBLES_EQUAL(1.0, bench.last_telemetry.speed_limit_mm_per_s, 1e-12);
  CHECK(bench.commands.push({CommandKind::SetSpeedLimit, 5.0}));
  bench.cycles(1);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Clamped);
  DOUBLES_EQUAL(1.0, bench.last_telemetry.speed_limit_mm_per_s, 1e-12);
  CHECK(bench.commands.push({CommandKind::SetSpeedLimit, 0.25}));
  bench.cycles(1);
  CHECK(bench.last_telemetry.last_parameter_outcome == ParameterOutcome::Applied);
  DOUBLES_EQUAL(0.25, bench.last_telemetry.speed_limit_mm_per_s, 1e-12);
  bench.move_device_to(kHomeDevice - Eigen::Vector3d(100.0, 0.0, 0.0), 500.0);
  const Eigen::Vector3d before = bench.controller->virtual_tip_mm();
  CHECK(bench.cycle() == CycleStatus::Running);
  DOUBLES_EQUAL(0.25e-3, (bench.controller->virtual_tip_mm() - before).cwiseAbs().sum(), 1e-12);
}

// Issue 29: the wall's feel is the operator's like the other parameters: taken live, clamped to
// what the cycle renders stably, and 0 means none (not a refusal).
TEST(Controller, TheWallsDampingFrictionAndSpeedLimitingAreSetLiveAndClamped) {
  Bench bench(config());
  bench.cycles(5);
  DOUBLES_EQUAL(0.0, bench.last_telemetry.damping_n_s_per_m, 0.0);
  DOUBLES_EQUAL(0.0, bench.last_telemetry.friction, 0.0);
  CHECK(bench.last_telemetry.speed_limiting == engine::SpeedLimiting::Cap);
  const struct {
    CommandKind kind;
    double value;
    ParameterOutcome outcome;
    double damping, friction;
    engine::SpeedLimiting limiting;
  } steps[] = {
      {CommandKind::SetDamping, 40.0, ParameterOutcome::Applied, 40.0, 0.0, engine::SpeedLimiting::Cap},
      {CommandKind::SetDamping, 500.0, ParameterOutcome::Clamped, 100.0, 0.0, engine::SpeedLimiting::Cap},
      {CommandKind::SetDamping, -1.0, ParameterOutcome::Refused, 100.0, 0.0, engine::SpeedLimiting::Cap},
      {CommandKind::SetFriction, 0.3, ParameterOutcome::Applied, 100.0, 0.3, engine::SpeedLimiting::Cap},
      {CommandKind::SetFriction, 1.5, ParameterOutcome::Clamped, 100.0, 1.0, engine::SpeedLimiting::Cap},
      {CommandKind::SetFriction, std::numeric_limits<double>::quiet_NaN(), ParameterOutcome::Refused, 100.0, 1.0,
       engine::SpeedLimiting::Cap},
      {CommandKind::SetSpeedLimiting, 1.0, ParameterOutcome::Applied, 100.0, 1.0, engine::SpeedLimiting::Penalty},
      {CommandKind::SetSpeedLimiting, 0.5, ParameterOutcome::Refused, 100.0, 1.0, engine::SpeedLimiting::Penalty},
      {CommandKind::SetSpeedLimiting, 0.0, ParameterOutcome::Applied, 100.0, 1.0, engine::SpeedLimiting::Cap},
      {CommandKind::SetFriction, 0.0, ParameterOutcome::Applied, 100.0, 0.0, engine::SpeedLimiting::Cap},
      {CommandKind::SetDamping, 0.0, ParameterOutcome::Applied, 0.0, 0.0, engine::SpeedLimiting::Cap},
  };
  for (const auto& step : steps) {
    CHECK(bench.display_commands.push({step.kind, step.value, CommandSource::Display}));
    bench.cycles(1);
    CHECK_TEXT(bench.last_telemetry.last_parameter == step.kind, command_kind_name(step.kind));
    CHECK_TEXT(bench.last_telemetry.last_parameter_outcome == step.outcome, command_kind_name(step.kind));
    DOUBLES_EQUAL(step.damping, bench.last_telemetry.damping_n_s_per_m, 0.0);
    DOUBLES_EQUAL(step.friction, bench.last_telemetry.friction, 0.0);
    CHECK(bench.last_telemetry.speed_limiting == step.limiting);
  }
  CHECK(bench.controller->safe_reason() == SafeReason::None);
}

// Issue 18, item 4: on the rig a handle resting 5 mm from the tool used to pull the tool (and the
// mill) 30 ms after the spindle came on, with 5 N on the handle. A held start does nothing until the
// hand is held as for a reset: still for the still time, near the tool.
TEST(Controller, AHeldStartIgnoresAHandRestingAwayFromTheToolAndWritesNoForce) {
  ControllerConfig c = config();
  c.start_held = true;
  Bench bench(c);
  bench.device.hold_at(kHomeDevice.x() + 50.0, kHomeDevice.y(), kHomeDevice.z());  // 5 mm (world) away
  bench.cycles(2000);
  CHECK(bench.controller->waiting_for_hand());
  CHECK((bench.controller->virtual_tip_mm() - kHomeWorld).norm() < 1e-12);
  DOUBLES_EQUAL(0.0, bench.force_written(), 0.0);
  CHECK(bench.controller->safe_reason() == SafeReason::None);
}

TEST(Controller, AHeldStartBeginsOnceTheHandIsHeldStillNearTheToolAndRampsTheForceIn) {
  ControllerConfig c = config();
  c.start_held = true;
  Bench bench(c);
  bench.device.hold_at(kHomeDevice.x() + 2.0, kHomeDevice.y(), kHomeDevice.z());  // near, still
  bench.cycles(400);
  CHECK(bench.controller->waiting_for_hand());  // not still for long enough yet
  bench.cycles(200);
  CHECK_FALSE(bench.controller->waiting_for_hand());
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(30.0, 0.0, 0.0), 500.0);
  CHECK(bench.controller->virtual_tip_mm().x() > kHomeWorld.x() + 1.0);  // it follows now
}

TEST(Controller, WithoutAHeldStartTheToolFollowsFromTheFirstCycle) {
  Bench bench;
  CHECK_FALSE(bench.controller->waiting_for_hand());
  bench.move_device_to(kHomeDevice + Eigen::Vector3d(30.0, 0.0, 0.0), 500.0);
  CHECK(bench.controller->virtual_tip_mm().x() > kHomeWorld.x() + 1.0);
}
