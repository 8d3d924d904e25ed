// The MachineLink contract (hal/machine_link.hpp), written once against hal::MachineLink& and run
// against every backend: the CY545 driver talking to the fake CY545 chip on a pseudo-terminal
// (virtual time: deterministic, a homing in milliseconds), and the spy the machine side's tests use.
// A backend is a small fixture (MachineLinkBackend) that makes the link, says what time it is, lets
// time pass, and reports what reached the machine, so that "refused, nothing sent" is measured at
// the machine and not by the link's own word.
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <string>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/sim_facts.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/machine_link.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_clock.hpp"
#include "sim/mill/simulated_mill.hpp"
#include "tests/fakes/spy_machine_link.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::MachineFault;
using hal::MachineLink;
using hal::MachineRefusal;
using hal::MachineResult;
using hal::MachineState;
using hal::MachineTarget;
using hal::MonotonicNs;

namespace {

constexpr MonotonicNs kMs = 1'000'000;
constexpr MonotonicNs kUpdateBoundNs = 500 * kMs;  // generous for one update's call: the contract is "by the deadline"
using MachineSteps = std::array<std::int64_t, 3>;

// What a contract case needs of a backend beyond the link itself.
struct MachineLinkBackend {
  MachineLinkBackend() = default;
  MachineLinkBackend(const MachineLinkBackend&) = delete;
  MachineLinkBackend& operator=(const MachineLinkBackend&) = delete;
  virtual ~MachineLinkBackend() = default;

  virtual MachineLink& link() = 0;
  // The clock the link runs on (the deadlines' time).
  virtual MonotonicNs now_ns() = 0;
  // Lets time pass, as between two machine updates.
  virtual void wait_ns(MonotonicNs ns) = 0;
  // How much has reached the machine so far (a count that grows with every command sent).
  virtual std::uint64_t sent() = 0;
  // Where the machine's motors stand, in motor steps (from an arbitrary origin: compare differences).
  virtual MachineSteps machine_steps() = 0;
  virtual bool machine_spindle_on() = 0;
  virtual bool machine_drivers_on() = 0;
  // Faults: the controller stops answering / its replies turn to garbage. False when the backend
  // cannot do it (the case then fails: instantiate it ignored for that backend).
  virtual bool silence_controller() = 0;
  virtual bool garble_replies() = 0;

  MonotonicNs in(MonotonicNs ns) { return now_ns() + ns; }
  MonotonicNs homing_deadline() { return in(link().homing_bound_ns() + 1000 * kMs); }
};

// ---- The CY545 driver against the fake chip on a pty, on the fake's virtual clock.

// The simulated mill without backlash and every axis just above its home switch, and a homing that
// approaches in legs of 4 steps: homing is then a handful of legs and queries (the driver's homing
// itself, and from mid-travel, is tested in tests/hal/cy545/cy545_link_tests.cpp).
sim::MillConfig quick_homing_mill() {
  sim::MillConfig config = board::sim::kMillConfig;
  for (sim::MillAxisConfig& axis : config.axes) {
    axis.backlash_steps = 0;
    axis.initial_position_steps = axis.home_switch_edge_steps + 2;
  }
  return config;
}

hal::cy545::Cy545Config quick_homing_config() {
  hal::cy545::Cy545Config config = board::sherline_suzuki::kCy545;
  config.motion.homing_chunk_steps = 4;
  return config;
}

struct Cy545Backend final : MachineLinkBackend {
  sim::SimulatedMill mill{quick_homing_mill()};
  sim::cy545::FakeCy545 fake{mill, board::sim::kMmc4sWiring, 0};
  sim::cy545::FakeCy545Clock clock{fake, 0, board::sim::kBaud};
  hal::cy545::SerialPort port;
  bool opened = open_port(port, fake.slave_path());
  hal::cy545::Cy545Link cy545{port, clock, quick_homing_config()};

  static bool open_port(hal::cy545::SerialPort& serial, const std::string& path) {
    char error[256] = {};
    CHECK_TEXT(serial.open(path.c_str(), board::sim::kBaud, error), error);
    return true;
  }
  // Hands the fake whatever bytes are still on their way through the pty.
  void settle() {
    static_cast<void>(clock.now_ns());
    while (fake.wait_for_input(2)) {
      static_cast<void>(clock.now_ns());
    }
  }

  MachineLink& link() override { return cy545; }
  MonotonicNs now_ns() override { return clock.now_ns(); }
  void wait_ns(MonotonicNs ns) override { clock.sleep_until_ns(clock.now_ns() + ns); }
  std::uint64_t sent() override {
    settle();
    return static_cast<std::uint64_t>(fake.pty_counters().bytes_read);
  }
  MachineSteps machine_steps() override {
    settle();
    return {mill.motor_position_steps(sim::Axis::x), mill.motor_position_steps(sim::Axis::y),
            mill.motor_position_steps(sim::Axis::z)};
  }
  bool machine_spindle_on() override {
    settle();
    return mill.spindle_on();
  }
  bool machine_drivers_on() override {
    settle();
    return mill.drivers_enabled();
  }
  bool silence_controller() override {
    fake.set_replies_suppressed(true);
    return true;
  }
  bool garble_replies() override {
    fake.set_replies_garbled(true);
    return true;
  }
};

// ---- The spy: its machine is itself (what it recorded), on a time of its own.

struct SpyBackend final : MachineLinkBackend {
  test::SpyMachineLink spy;
  MonotonicNs time_ns = 1'000 * kMs;

  MachineLink& link() override { return spy; }
  MonotonicNs now_ns() override { return time_ns; }
  void wait_ns(MonotonicNs ns) override { time_ns += ns; }
  std::uint64_t sent() override { return spy.moves().size(); }
  // Where the motors are: the spy's targets count from the last home, so walk its calls (home()
  // goes to step 0 of the machine; declare_home() makes where it stands the new step 0).
  MachineSteps machine_steps() override {
    MachineSteps at{0, 0, 0};
    MachineSteps origin{0, 0, 0};
    for (const test::SpyCall& call : spy.calls()) {
      if (!call.result.done) {
        continue;
      }
      if (call.kind == test::MachineCall::Home) {
        at = origin = {0, 0, 0};
      } else if (call.kind == test::MachineCall::DeclareHome) {
        origin = at;
      } else if (call.kind == test::MachineCall::Move) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
          at[axis] = origin[axis] + call.target.motor_steps[axis];
        }
      }
    }
    return at;
  }
  bool machine_spindle_on() override { return spy.status().spindle_on; }
  bool machine_drivers_on() override { return spy.status().drivers_on; }
  // The spy's scripted faults: its next query answers as the CY545 link's would.
  bool silence_controller() override {
    spy.fail_next(test::MachineCall::Verify, MachineFault::Timeout);
    return true;
  }
  bool garble_replies() override {
    spy.fail_next(test::MachineCall::Verify, MachineFault::GarbledReply);
    return true;
  }
};

MachineTarget target(std::int32_t x, std::int32_t y, std::int32_t z, std::array<std::uint8_t, 3> order, bool cutting) {
  return {{x, y, z}, order, cutting};
}

MachineSteps difference(const MachineSteps& after, const MachineSteps& before) {
  return {after[0] - before[0], after[1] - before[1], after[2] - before[2]};
}

void check_steps(const std::array<std::int32_t, 3>& expected, const std::array<std::int32_t, 3>& actual) {
  LONGS_EQUAL(expected[0], actual[0]);
  LONGS_EQUAL(expected[1], actual[1]);
  LONGS_EQUAL(expected[2], actual[2]);
}

void check_steps(const std::array<std::int32_t, 3>& expected, const MachineSteps& actual) {
  LONGS_EQUAL(expected[0], actual[0]);
  LONGS_EQUAL(expected[1], actual[1]);
  LONGS_EQUAL(expected[2], actual[2]);
}

void check_refused(const MachineResult& result, MachineRefusal refusal) {
  CHECK_FALSE(result.done);
  LONGS_EQUAL(static_cast<int>(refusal), static_cast<int>(result.refusal));
  LONGS_EQUAL(static_cast<int>(MachineFault::None), static_cast<int>(result.fault));
}

void check_state(MachineState expected, MachineState actual) {
  LONGS_EQUAL(static_cast<int>(expected), static_cast<int>(actual));
}

void start_and_home(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  CHECK(link.start(backend.in(2'000 * kMs)).done);
  CHECK(link.home(backend.homing_deadline()).done);
}

}  // namespace

// ---- The contract, once. Each case takes any backend.
namespace contract {

void StartThenHomeGivesHomed(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  const MachineResult started = link.start(backend.in(2'000 * kMs));
  CHECK(started.done);
  CHECK_FALSE(link.status().homed);
  CHECK(link.homing_bound_ns() > 0);
  const MachineResult homed = link.home(backend.homing_deadline());
  CHECK(homed.done);
  LONGS_EQUAL(static_cast<int>(MachineRefusal::None), static_cast<int>(homed.refusal));
  check_state(MachineState::Homed, link.status().state);
  CHECK(link.status().homed);
  LONGS_EQUAL(static_cast<int>(MachineFault::None), static_cast<int>(link.status().fault));
  check_steps({0, 0, 0}, link.status().commanded_steps);  // motor steps count from home
  for (const int approach : link.home_approach()) {
    CHECK(approach == 1 || approach == -1);
  }
}

void MovesBeforeHomingAreRefusedNotHomedAndSendNothing(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  const std::uint64_t before_start = backend.sent();
  check_refused(link.move(target(1, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::NotHomed);
  LONGS_EQUAL(before_start, backend.sent());
  CHECK(link.start(backend.in(2'000 * kMs)).done);
  CHECK(link.set_spindle(true, backend.in(kUpdateBoundNs)).done);
  const std::uint64_t before = backend.sent();
  const MachineSteps where = backend.machine_steps();
  check_refused(link.move(target(1, 2, 3, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::NotHomed);
  check_refused(link.move(target(1, 2, 3, {2, 0, 1}, true), backend.in(kUpdateBoundNs)), MachineRefusal::NotHomed);
  LONGS_EQUAL(before, backend.sent());
  check_steps({0, 0, 0}, difference(backend.machine_steps(), where));
  LONGS_EQUAL(0, link.status().moves_done);
}

void AMoveIsDoneAndTheCommandedStepsAreItsTarget(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  const MachineSteps home = backend.machine_steps();
  CHECK(link.set_spindle(true, backend.in(kUpdateBoundNs)).done);
  const std::uint64_t moves_before = link.status().moves_done;
  const std::uint64_t sent_before = backend.sent();
  const MachineResult first = link.move(target(3, -2, 4, {2, 0, 1}, true), backend.in(kUpdateBoundNs));
  CHECK(first.done);
  check_steps({3, -2, 4}, link.status().commanded_steps);
  check_steps({3, -2, 4}, difference(backend.machine_steps(), home));
  CHECK(backend.sent() > sent_before);  // the probe the refusal cases rely on sees a move
  // Targets are absolute: the second move goes to (5, 1, 4), not by it.
  CHECK(link.move(target(5, 1, 4, {1, 0, 2}, false), backend.in(kUpdateBoundNs)).done);
  check_steps({5, 1, 4}, link.status().commanded_steps);
  check_steps({5, 1, 4}, difference(backend.machine_steps(), home));
  LONGS_EQUAL(moves_before + 2, link.status().moves_done);
  check_state(MachineState::Homed, link.status().state);
}

void ABadTargetIsRefusedBadTargetAndSendsNothing(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  const std::uint64_t before = backend.sent();
  const std::array<std::uint8_t, 3> not_permutations[] = {{0, 0, 2}, {0, 1, 3}, {2, 2, 2}, {255, 1, 0}};
  for (const std::array<std::uint8_t, 3>& order : not_permutations) {
    check_refused(link.move(target(1, 0, 0, order, false), backend.in(kUpdateBoundNs)), MachineRefusal::BadTarget);
  }
  // Beyond any controller's range (the CY545's is 24 bits).
  constexpr std::int32_t kFar = std::numeric_limits<std::int32_t>::max();
  check_refused(link.move(target(kFar, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::BadTarget);
  check_refused(link.move(target(0, 0, -kFar, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::BadTarget);
  LONGS_EQUAL(before, backend.sent());
  check_steps({0, 0, 0}, link.status().commanded_steps);
  LONGS_EQUAL(0, link.status().moves_done);
}

void ACuttingMoveWithTheSpindleOffIsRefusedSpindleOff(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  const std::uint64_t before = backend.sent();
  check_refused(link.move(target(2, 0, 0, {0, 1, 2}, true), backend.in(kUpdateBoundNs)), MachineRefusal::SpindleOff);
  LONGS_EQUAL(before, backend.sent());
  // Turned on and off again: the interlock follows the spindle, not its history.
  CHECK(link.set_spindle(true, backend.in(kUpdateBoundNs)).done);
  CHECK(link.set_spindle(false, backend.in(kUpdateBoundNs)).done);
  const std::uint64_t after_spindle = backend.sent();
  check_refused(link.move(target(2, 0, 0, {0, 1, 2}, true), backend.in(kUpdateBoundNs)), MachineRefusal::SpindleOff);
  LONGS_EQUAL(after_spindle, backend.sent());
  check_steps({0, 0, 0}, link.status().commanded_steps);
  CHECK(link.move(target(2, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);  // not cutting: allowed
  check_steps({2, 0, 0}, link.status().commanded_steps);
}

void HoldRefusesMovesUntilResume(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK(link.set_spindle(true, backend.in(kUpdateBoundNs)).done);
  CHECK(link.move(target(1, 1, 1, {0, 1, 2}, true), backend.in(kUpdateBoundNs)).done);
  link.hold();
  check_state(MachineState::Held, link.status().state);
  const std::uint64_t before = backend.sent();
  for (int update = 0; update < 3; ++update) {
    check_refused(link.move(target(2, 1, 1, {0, 1, 2}, true), backend.in(kUpdateBoundNs)), MachineRefusal::Held);
    backend.wait_ns(33 * kMs);
  }
  LONGS_EQUAL(before, backend.sent());
  check_steps({1, 1, 1}, link.status().commanded_steps);
  link.resume();
  check_state(MachineState::Homed, link.status().state);
  CHECK(link.move(target(2, 1, 1, {0, 1, 2}, true), backend.in(kUpdateBoundNs)).done);
  check_steps({2, 1, 1}, link.status().commanded_steps);
}

void StopTurnsTheSpindleOffAndLeavesTheLinkStopped(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK(link.set_spindle(true, backend.in(kUpdateBoundNs)).done);
  CHECK(link.move(target(1, 2, 3, {0, 1, 2}, true), backend.in(kUpdateBoundNs)).done);
  CHECK(backend.machine_spindle_on());
  const MachineResult stopped = link.stop(backend.in(2'000 * kMs));
  CHECK(stopped.done);
  LONGS_EQUAL(static_cast<int>(MachineFault::None), static_cast<int>(stopped.fault));
  check_state(MachineState::Stopped, link.status().state);
  CHECK_FALSE(link.status().spindle_on);
  CHECK_FALSE(backend.machine_spindle_on());
}

void StopTurnsTheDriversOff(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK(link.move(target(1, 2, 3, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);
  CHECK(link.status().drivers_on);  // a move needs them
  CHECK(backend.machine_drivers_on());
  CHECK(link.stop(backend.in(2'000 * kMs)).done);
  CHECK_FALSE(link.status().drivers_on);
  CHECK_FALSE(backend.machine_drivers_on());
}

void AfterAStopMovesAreRefusedUntilHomedAgain(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK(link.move(target(1, 2, 3, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);
  CHECK(link.stop(backend.in(2'000 * kMs)).done);
  CHECK_FALSE(link.status().homed);  // limp axes may have moved
  const std::uint64_t before = backend.sent();
  check_refused(link.move(target(2, 2, 3, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::NotHomed);
  link.resume();  // a resume is no homing
  check_refused(link.move(target(2, 2, 3, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::NotHomed);
  LONGS_EQUAL(before, backend.sent());
  CHECK(link.home(backend.homing_deadline()).done);
  check_state(MachineState::Homed, link.status().state);
  check_steps({0, 0, 0}, link.status().commanded_steps);
  CHECK(link.move(target(2, 2, 3, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);
  check_steps({2, 2, 3}, link.status().commanded_steps);
}

void DeclaredHomeMakesWhereTheToolStandsStepZero(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  CHECK(link.start(backend.in(2'000 * kMs)).done);
  CHECK(link.declare_home(backend.in(kUpdateBoundNs)).done);
  check_state(MachineState::Homed, link.status().state);
  CHECK(link.status().homed);
  CHECK(link.move(target(4, 0, 2, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);
  const MachineSteps mark = backend.machine_steps();
  CHECK(link.declare_home(backend.in(kUpdateBoundNs)).done);
  check_steps({0, 0, 0}, link.status().commanded_steps);
  CHECK(link.move(target(1, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);
  check_steps({1, 0, 0}, difference(backend.machine_steps(), mark));  // from the mark, not from the first home
}

void VerifyAfterMovesIsDone(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK(link.verify(backend.in(kUpdateBoundNs)).done);
  const MachineTarget path[] = {target(3, 0, 0, {0, 1, 2}, false), target(3, 4, -2, {2, 1, 0}, false),
                                target(-1, 4, -2, {1, 0, 2}, false)};
  for (const MachineTarget& step : path) {
    CHECK(link.move(step, backend.in(kUpdateBoundNs)).done);
    const MachineResult verified = link.verify(backend.in(kUpdateBoundNs));
    CHECK(verified.done);
    LONGS_EQUAL(static_cast<int>(MachineFault::None), static_cast<int>(verified.fault));
  }
  LONGS_EQUAL(static_cast<int>(MachineFault::None), static_cast<int>(link.status().fault));
}

void KeepAliveAnswersDoneAtEveryUpdate(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  CHECK(link.start(backend.in(2'000 * kMs)).done);
  CHECK(link.keep_alive(backend.in(kUpdateBoundNs)).done);  // before homing too: homing may be long
  CHECK(link.home(backend.homing_deadline()).done);
  for (int update = 0; update < 40; ++update) {  // more than a second of 30 Hz updates: due several times
    const MachineResult alive = link.keep_alive(backend.in(60 * kMs));
    CHECK(alive.done);
    LONGS_EQUAL(static_cast<int>(MachineFault::None), static_cast<int>(alive.fault));
    backend.wait_ns(33 * kMs);
  }
  check_state(MachineState::Homed, link.status().state);
  CHECK(link.move(target(1, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)).done);  // moves undisturbed
}

void EveryCallReturnsByItsDeadline(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  const auto check_by = [&](const char* call, MonotonicNs deadline) {
    CHECK_TEXT(backend.now_ns() <= deadline, call);
  };
  MonotonicNs deadline = backend.in(2'000 * kMs);
  CHECK(link.start(deadline).done);
  check_by("start", deadline);
  deadline = backend.homing_deadline();
  CHECK(link.home(deadline).done);
  check_by("home", deadline);
  deadline = backend.in(60 * kMs);
  CHECK(link.keep_alive(deadline).done);
  check_by("keep_alive", deadline);
  deadline = backend.in(60 * kMs);
  CHECK(link.set_spindle(true, deadline).done);
  check_by("set_spindle", deadline);
  for (std::int32_t x = 1; x <= 5; ++x) {
    deadline = backend.in(60 * kMs);  // two updates' time for a move of 2 steps
    CHECK(link.move(target(x, x, 0, {0, 1, 2}, true), deadline).done);
    check_by("move", deadline);
  }
  deadline = backend.in(60 * kMs);
  CHECK(link.verify(deadline).done);
  check_by("verify", deadline);
  deadline = backend.in(60 * kMs);
  CHECK(link.declare_home(deadline).done);
  check_by("declare_home", deadline);
  deadline = backend.in(200 * kMs);
  CHECK(link.stop(deadline).done);
  check_by("stop", deadline);
}

void AControllerThatStopsAnsweringIsAFaultByTheDeadline(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK_TEXT(backend.silence_controller(), "this backend cannot silence its controller");
  const MonotonicNs deadline = backend.in(kUpdateBoundNs);
  const MachineResult verified = link.verify(deadline);
  CHECK(backend.now_ns() <= deadline);  // a fault, not a hang
  CHECK_FALSE(verified.done);
  LONGS_EQUAL(static_cast<int>(MachineFault::Timeout), static_cast<int>(verified.fault));
  LONGS_EQUAL(static_cast<int>(MachineFault::Timeout), static_cast<int>(link.status().fault));
  check_state(MachineState::Fault, link.status().state);
}

void ALatchedFaultRefusesMovesAndHomingFaulted(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  start_and_home(backend);
  CHECK_TEXT(backend.garble_replies(), "this backend cannot garble its replies");
  const MachineResult verified = link.verify(backend.in(kUpdateBoundNs));
  CHECK_FALSE(verified.done);
  LONGS_EQUAL(static_cast<int>(MachineFault::GarbledReply), static_cast<int>(verified.fault));
  check_state(MachineState::Fault, link.status().state);
  const std::uint64_t before = backend.sent();
  check_refused(link.move(target(1, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::Faulted);
  check_refused(link.home(backend.homing_deadline()), MachineRefusal::Faulted);
  LONGS_EQUAL(before, backend.sent());
  LONGS_EQUAL(static_cast<int>(MachineFault::GarbledReply), static_cast<int>(link.status().fault));  // latched
}

void AbortOnsFlagMakesHomeGiveUpAborted(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  std::atomic<bool> stop_asked{false};
  link.abort_on(&stop_asked);
  CHECK(link.start(backend.in(2'000 * kMs)).done);
  const MachineSteps before = backend.machine_steps();
  stop_asked.store(true);
  const MachineResult homed = link.home(backend.homing_deadline());
  check_refused(homed, MachineRefusal::Aborted);
  CHECK_FALSE(link.status().homed);
  CHECK_FALSE(link.status().spindle_on);  // outputs off
  CHECK_FALSE(link.status().drivers_on);
  CHECK_FALSE(backend.machine_drivers_on());
  check_steps({0, 0, 0}, difference(backend.machine_steps(), before));  // given up before the first leg
  check_refused(link.move(target(1, 0, 0, {0, 1, 2}, false), backend.in(kUpdateBoundNs)), MachineRefusal::NotHomed);
}

void AbortOnsFlagMakesStartGiveUpAborted(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  std::atomic<bool> stop_asked{true};
  link.abort_on(&stop_asked);
  check_refused(link.start(backend.in(2'000 * kMs)), MachineRefusal::Aborted);
  CHECK_FALSE(link.status().homed);
  CHECK_FALSE(backend.machine_drivers_on());
}

// The MMC-4S board's latches keep the outputs across a program's restart (and the chip's "I"): a
// start that gives up must still leave them off, as a start that completes does.
void AnAbortedStartLeavesOffTheOutputsAnEarlierRunLeftOn(MachineLinkBackend& backend) {
  MachineLink& link = backend.link();
  std::atomic<bool> stop_asked{false};
  link.abort_on(&stop_asked);
  start_and_home(backend);
  CHECK(link.set_spindle(true, backend.in(kUpdateBoundNs)).done);
  CHECK(link.move(target(1, 1, 1, {0, 1, 2}, true), backend.in(kUpdateBoundNs)).done);
  CHECK(backend.machine_spindle_on());
  stop_asked.store(true);  // the next run's operator asks for a stop while the mill wakes
  check_refused(link.start(backend.in(2'000 * kMs)), MachineRefusal::Aborted);
  CHECK_FALSE(backend.machine_spindle_on());
  CHECK_FALSE(backend.machine_drivers_on());
  CHECK_FALSE(link.status().spindle_on);
  CHECK_FALSE(link.status().drivers_on);
}

}  // namespace contract

// ---- Every case for every backend.
#define MACHINE_LINK_CONTRACT_ON_CY545(name) \
  TEST(MachineLinkContractOnCy545, name) {   \
    Cy545Backend backend;                    \
    contract::name(backend);                 \
  }
#define MACHINE_LINK_CONTRACT_ON_SPY(name) \
  TEST(MachineLinkContractOnSpy, name) {   \
    SpyBackend backend;                    \
    contract::name(backend);               \
  }
#define MACHINE_LINK_CONTRACT_IGNORED_ON_CY545(name) \
  IGNORE_TEST(MachineLinkContractOnCy545, name) {    \
    Cy545Backend backend;                            \
    contract::name(backend);                         \
  }
#define MACHINE_LINK_CONTRACT_IGNORED_ON_SPY(name) \
  IGNORE_TEST(MachineLinkContractOnSpy, name) {    \
    SpyBackend backend;                            \
    contract::name(backend);                       \
  }

TEST_GROUP(MachineLinkContractOnCy545){};
TEST_GROUP(MachineLinkContractOnSpy){};

MACHINE_LINK_CONTRACT_ON_CY545(StartThenHomeGivesHomed)
MACHINE_LINK_CONTRACT_ON_SPY(StartThenHomeGivesHomed)

MACHINE_LINK_CONTRACT_ON_CY545(MovesBeforeHomingAreRefusedNotHomedAndSendNothing)
MACHINE_LINK_CONTRACT_ON_SPY(MovesBeforeHomingAreRefusedNotHomedAndSendNothing)

MACHINE_LINK_CONTRACT_ON_CY545(AMoveIsDoneAndTheCommandedStepsAreItsTarget)
MACHINE_LINK_CONTRACT_ON_SPY(AMoveIsDoneAndTheCommandedStepsAreItsTarget)

MACHINE_LINK_CONTRACT_ON_CY545(ABadTargetIsRefusedBadTargetAndSendsNothing)
MACHINE_LINK_CONTRACT_ON_SPY(ABadTargetIsRefusedBadTargetAndSendsNothing)

MACHINE_LINK_CONTRACT_ON_CY545(ACuttingMoveWithTheSpindleOffIsRefusedSpindleOff)
MACHINE_LINK_CONTRACT_ON_SPY(ACuttingMoveWithTheSpindleOffIsRefusedSpindleOff)

MACHINE_LINK_CONTRACT_ON_CY545(HoldRefusesMovesUntilResume)
MACHINE_LINK_CONTRACT_ON_SPY(HoldRefusesMovesUntilResume)

MACHINE_LINK_CONTRACT_ON_CY545(StopTurnsTheSpindleOffAndLeavesTheLinkStopped)
MACHINE_LINK_CONTRACT_ON_SPY(StopTurnsTheSpindleOffAndLeavesTheLinkStopped)

MACHINE_LINK_CONTRACT_ON_CY545(StopTurnsTheDriversOff)
MACHINE_LINK_CONTRACT_ON_SPY(StopTurnsTheDriversOff)

MACHINE_LINK_CONTRACT_ON_CY545(AfterAStopMovesAreRefusedUntilHomedAgain)
MACHINE_LINK_CONTRACT_ON_SPY(AfterAStopMovesAreRefusedUntilHomedAgain)

MACHINE_LINK_CONTRACT_ON_CY545(DeclaredHomeMakesWhereTheToolStandsStepZero)
MACHINE_LINK_CONTRACT_ON_SPY(DeclaredHomeMakesWhereTheToolStandsStepZero)

MACHINE_LINK_CONTRACT_ON_CY545(VerifyAfterMovesIsDone)
MACHINE_LINK_CONTRACT_ON_SPY(VerifyAfterMovesIsDone)

MACHINE_LINK_CONTRACT_ON_CY545(KeepAliveAnswersDoneAtEveryUpdate)
MACHINE_LINK_CONTRACT_ON_SPY(KeepAliveAnswersDoneAtEveryUpdate)

MACHINE_LINK_CONTRACT_ON_CY545(EveryCallReturnsByItsDeadline)
MACHINE_LINK_CONTRACT_ON_SPY(EveryCallReturnsByItsDeadline)

MACHINE_LINK_CONTRACT_ON_CY545(AControllerThatStopsAnsweringIsAFaultByTheDeadline)
MACHINE_LINK_CONTRACT_ON_SPY(AControllerThatStopsAnsweringIsAFaultByTheDeadline)

MACHINE_LINK_CONTRACT_ON_CY545(ALatchedFaultRefusesMovesAndHomingFaulted)
MACHINE_LINK_CONTRACT_ON_SPY(ALatchedFaultRefusesMovesAndHomingFaulted)

MACHINE_LINK_CONTRACT_ON_CY545(AbortOnsFlagMakesHomeGiveUpAborted)
MACHINE_LINK_CONTRACT_ON_SPY(AbortOnsFlagMakesHomeGiveUpAborted)

MACHINE_LINK_CONTRACT_ON_CY545(AbortOnsFlagMakesStartGiveUpAborted)
MACHINE_LINK_CONTRACT_ON_SPY(AbortOnsFlagMakesStartGiveUpAborted)

// Found by this case: start() gave up in its wake-up loop before turning any output off.
MACHINE_LINK_CONTRACT_ON_CY545(AnAbortedStartLeavesOffTheOutputsAnEarlierRunLeftOn)
MACHINE_LINK_CONTRACT_ON_SPY(AnAbortedStartLeavesOffTheOutputsAnEarlierRunLeftOn)
