// The LinuxCNC link against the real LinuxCNC: sim/linuxcnc_mill's headless simulated mill, started
// for each case by sim/linuxcnc_mill/linuxcnc-sim.sh (run_linuxcnc_tests.sh hands its path and an
// instance folder in LCNC_SIM and LCNC_DIR, and stops LinuxCNC whatever happens). Ctest label
// `linuxcnc`; one LinuxCNC per host, so the cases hold the resource lock `linuxcnc`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/wait.h>

#include "hal/linuxcnc/linuxcnc_link.hpp"
#include "hal/linuxcnc/tcp_line_channel.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::hal;
using namespace stencil::hal::linuxcnc;

namespace {

constexpr MonotonicNs kMs = 1'000'000;
constexpr MonotonicNs kSecond = 1000 * kMs;

std::string env(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : "";
}

// linuxcnc-sim.sh COMMAND DIR ARGS: its exit status.
int sim(const std::string& command, const std::string& args = "") {
  const std::string line = "bash '" + env("LCNC_SIM") + "' " + command + " '" + env("LCNC_DIR") + "' " + args + " >> '" +
                           env("LCNC_DIR") + ".log' 2>&1";
  const int status = std::system(line.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

template <std::size_t N>
void put(std::array<char, N>& field, const std::string& text) {
  field = {};
  std::memcpy(field.data(), text.data(), std::min(text.size(), N - 1));
}

// sim/linuxcnc_mill's mill: X 0..50, Y 0..25, Z 0..25 mm, passwords as linuxcnc-sim.sh's defaults.
LinuxcncConfig mill_config() {
  LinuxcncConfig config;
  put(config.address, "127.0.0.1");
  config.port = static_cast<std::uint16_t>(std::atoi(env("LCNC_SIM_PORT").empty() ? "5007" : env("LCNC_SIM_PORT").c_str()));
  put(config.connect_password, "SimMillHello");
  put(config.enable_password, "SimMillEnable");
  config.steps_per_mm = 640.0;
  config.travel_mm = {50.0, 25.0, 25.0};
  config.max_move_mm = 0.2;
  config.feed_mm_per_min = 300.0;
  return config;
}

MachineTarget at_mm(double x, double y, double z) {
  return {{static_cast<std::int32_t>(x * 640.0), static_cast<std::int32_t>(y * 640.0), static_cast<std::int32_t>(z * 640.0)},
          {0, 1, 2},
          true};
}

}  // namespace

TEST_GROUP(LinuxcncLink) {
  posix_clock::MonotonicClock clock;
  MonotonicNs in(MonotonicNs ns) { return clock.now_ns() + ns; }

  void setup() override {
    CHECK_TEXT(!env("LCNC_SIM").empty() && !env("LCNC_DIR").empty(),
               "run by run_linuxcnc_tests.sh, which sets LCNC_SIM and LCNC_DIR");
    CHECK_EQUAL_TEXT(0, sim("stop"), "linuxcnc-sim.sh stop");
  }
  void teardown() override { static_cast<void>(sim("stop")); }

  void start_mill() { CHECK_EQUAL_TEXT(0, sim("start"), "linuxcnc-sim.sh start (its log: LCNC_DIR.log)"); }

  // Started, homed, spindle on: ready to cut.
  void ready(LinuxcncLink& link) {
    const MachineResult started = link.start(in(5 * kSecond));
    CHECK_TEXT(started.done, link.last_error());
    const MachineResult homed = link.home(in(link.homing_bound_ns()));
    CHECK_TEXT(homed.done, link.last_error());
    CHECK_TEXT(link.set_spindle(true, in(kSecond)).done, link.last_error());
  }

  // Moves in steps of at most 0.2 mm to (x, y, z), one a tenth of a second, each update's look between.
  int moves = 0;  // sent by go()
  MachineResult go(LinuxcncLink& link, double x, double y, double z) {
    const MachineStatus now = link.status();
    double from[3] = {now.commanded_steps[0] / 640.0, now.commanded_steps[1] / 640.0, now.commanded_steps[2] / 640.0};
    const double to[3] = {x, y, z};
    for (int guard = 0; guard < 1000; ++guard) {
      bool there = true;
      for (int i = 0; i < 3; ++i) {
        const double step = std::clamp(to[i] - from[i], -0.19, 0.19);
        from[i] += step;
        there = there && std::fabs(to[i] - from[i]) < 1e-9;
      }
      const MachineResult moved = link.move(at_mm(from[0], from[1], from[2]), in(kSecond));
      if (!moved.done) {
        return moved;
      }
      ++moves;
      const MachineResult alive = link.keep_alive(in(kSecond));
      if (!alive.done || there) {
        return alive;
      }
    }
    return {false, MachineRefusal::None, MachineFault::None};
  }
};

TEST(LinuxcncLink, StartsHomesMovesAndStandsWhereItWasToldThenStopsWithTheMachineOff) {
  start_mill();
  LinuxcncLink link(clock, mill_config());
  ready(link);
  CHECK(link.status().state == MachineState::Homed);
  CHECK(link.status().homed);
  const MachineResult moved = go(link, 2.0, 1.5, 1.0);
  CHECK_TEXT(moved.done, link.last_error());
  clock.sleep_until_ns(in(300 * kMs));  // the last move's tenth of a second, and a margin
  CHECK_TEXT(link.verify(in(kSecond)).done, link.last_error());
  DOUBLES_EQUAL(2.0, link.actual_mm()[0], 0.002);
  DOUBLES_EQUAL(1.5, link.actual_mm()[1], 0.002);
  DOUBLES_EQUAL(1.0, link.actual_mm()[2], 0.002);
  CHECK_EQUAL(static_cast<std::uint64_t>(moves), link.status().moves_done);
  CHECK(link.stop(in(2 * kSecond)).done);
  CHECK(link.status().state == MachineState::Stopped);
  CHECK_FALSE(link.status().drivers_on);
  // Stopped: no move until homed again.
  CHECK(link.move(at_mm(2.1, 1.5, 1.0), in(kSecond)).refusal == MachineRefusal::NotHomed);
  CHECK_TEXT(link.home(in(link.homing_bound_ns())).done, link.last_error());
}

TEST(LinuxcncLink, NoMoveBeforeHomingNorWhileHeldNorBeyondTheTravelOrAnUpdatesReach) {
  start_mill();
  LinuxcncLink link(clock, mill_config());
  CHECK_TEXT(link.start(in(5 * kSecond)).done, link.last_error());
  CHECK(link.move(at_mm(0.1, 0.0, 0.0), in(kSecond)).refusal == MachineRefusal::NotHomed);
  CHECK_TEXT(link.home(in(link.homing_bound_ns())).done, link.last_error());
  CHECK(link.move(at_mm(0.1, 0.0, 0.0), in(kSecond)).refusal == MachineRefusal::SpindleOff);
  CHECK_TEXT(link.set_spindle(true, in(kSecond)).done, link.last_error());
  link.hold();
  CHECK(link.move(at_mm(0.1, 0.0, 0.0), in(kSecond)).refusal == MachineRefusal::Held);
  link.resume();
  CHECK(link.move(at_mm(0.5, 0.0, 0.0), in(kSecond)).refusal == MachineRefusal::TooLong);
  CHECK(link.move(at_mm(-0.1, 0.0, 0.0), in(kSecond)).refusal == MachineRefusal::BadTarget);
  CHECK_TEXT(link.move(at_mm(0.1, 0.0, 0.0), in(kSecond)).done, link.last_error());
  clock.sleep_until_ns(in(300 * kMs));
  CHECK_TEXT(link.keep_alive(in(kSecond)).done, link.last_error());
  CHECK_EQUAL(1U, link.status().moves_done);
}

TEST(LinuxcncLink, NotRunningIsNoAnswerNamingWhereItLooked) {
  LinuxcncLink link(clock, mill_config());
  const MachineResult started = link.start(in(2 * kSecond));
  CHECK_FALSE(started.done);
  CHECK(started.fault == MachineFault::NoAnswer);
  STRCMP_CONTAINS("nothing answers at 127.0.0.1 port", link.last_error());
  STRCMP_CONTAINS("Connection refused", link.last_error());
}

TEST(LinuxcncLink, DefaultPasswordsAreRefusedBeforeAnythingIsSentAndAWrongOneInLinuxcncsWords) {
  start_mill();
  LinuxcncConfig defaults = mill_config();
  put(defaults.connect_password, "EMC");
  put(defaults.enable_password, "EMCTOO");
  LinuxcncLink refused(clock, defaults);
  const MachineResult started = refused.start(in(2 * kSecond));
  CHECK(started.fault == MachineFault::OpenFailed);
  STRCMP_CONTAINS("default passwords (EMC, EMCTOO) are refused", refused.last_error());
  CHECK_EQUAL(0U, refused.status().bytes_sent);
  LinuxcncConfig wrong = mill_config();
  put(wrong.connect_password, "NotTheOne");
  LinuxcncLink nak(clock, wrong);
  CHECK(nak.start(in(2 * kSecond)).fault == MachineFault::CommandRefused);
  STRCMP_CONTAINS("LinuxCNC says \"HELLO NAK\"", nak.last_error());
}

TEST(LinuxcncLink, AnEstopPressedMidCutLatchesAFaultAtTheNextLookInLinuxcncsWords) {
  start_mill();
  LinuxcncLink link(clock, mill_config());
  ready(link);
  CHECK_TEXT(go(link, 1.0, 0.0, 0.0).done, link.last_error());
  CHECK_EQUAL(0, sim("estop", "press"));
  // The next machine update (8 Hz with LinuxCNC) sees it.
  clock.sleep_until_ns(in(125 * kMs));
  const MachineResult looked = link.keep_alive(in(kSecond));
  CHECK_FALSE(looked.done);
  CHECK(looked.fault == MachineFault::EstopPressed);
  STRCMP_CONTAINS("LinuxCNC is in e-stop", link.last_error());
  CHECK(link.move(at_mm(1.1, 0.0, 0.0), in(kSecond)).refusal == MachineRefusal::Faulted);
  // The stop still reaches LinuxCNC (machine off), and the first fault's words stay.
  static_cast<void>(link.stop(in(2 * kSecond)));
  CHECK(link.status().fault == MachineFault::EstopPressed);
  STRCMP_CONTAINS("LinuxCNC is in e-stop", link.last_error());
  // While the button is down, LinuxCNC cannot be started: refused in its own words.
  LinuxcncLink again(clock, mill_config());
  CHECK(again.start(in(5 * kSecond)).fault == MachineFault::EstopPressed);
}

TEST(LinuxcncLink, LinuxcncKilledMidCutIsALostConnection) {
  start_mill();
  LinuxcncLink link(clock, mill_config());
  ready(link);
  CHECK_TEXT(go(link, 1.0, 0.0, 0.0).done, link.last_error());
  CHECK_EQUAL(0, sim("kill"));
  const MachineResult looked = link.keep_alive(in(kSecond));
  CHECK_FALSE(looked.done);
  CHECK(looked.fault == MachineFault::PortClosed || looked.fault == MachineFault::WriteFailed);
  STRCMP_CONTAINS("the connection to linuxcncrsh", link.last_error());
  CHECK_FALSE(link.stop(in(kSecond)).done);  // nothing to tell any more: the fault stays
}

TEST(LinuxcncLink, AFollowingErrorLatchesAFaultWithLinuxcncsWords) {
  start_mill();
  LinuxcncLink link(clock, mill_config());
  ready(link);
  CHECK_EQUAL(0, sim("ferror", "0 0.5"));  // X's motor now follows at 0.5 mm/s
  MachineResult result = go(link, 3.0, 0.0, 0.0);
  for (int i = 0; i < 30 && result.done; ++i) {
    clock.sleep_until_ns(in(100 * kMs));
    result = link.keep_alive(in(kSecond));
  }
  CHECK_FALSE(result.done);
  CHECK(link.status().fault == MachineFault::ControllerError || link.status().fault == MachineFault::EstopPressed);
  STRCMP_CONTAINS("following error", link.last_error());
}

TEST(LinuxcncLink, AMoveLinuxcncRefusesIsAFaultInItsWords) {
  start_mill();
  LinuxcncConfig beyond = mill_config();
  beyond.travel_mm = {60.0, 25.0, 25.0};  // the link believes X reaches further than LinuxCNC's INI
  beyond.max_move_mm = 60.0;
  LinuxcncLink link(clock, beyond);
  ready(link);
  MachineResult result = link.move(at_mm(55.0, 0.0, 0.0), in(kSecond));
  for (int i = 0; i < 10 && result.done; ++i) {
    result = link.keep_alive(in(kSecond));
  }
  CHECK_FALSE(result.done);
  CHECK(link.status().fault == MachineFault::ControllerError);
  STRCMP_CONTAINS("would exceed", link.last_error());
}

// The path the planner checked is the path the mill moves: after homing, LinuxCNC's interpreter is in
// exact-path mode (G61: no blending of corners), millimetres and absolute, as a second connection
// (a get needs no enable) reads from LinuxCNC itself.
TEST(LinuxcncLink, AfterHomingLinuxcncMovesInExactPathMillimetresAbsolute) {
  start_mill();
  LinuxcncLink link(clock, mill_config());
  ready(link);
  TcpLineChannel watcher(clock);
  CHECK(watcher.connect("127.0.0.1", mill_config().port, in(kSecond)) == LineStatus::Ok);
  std::string_view line;
  CHECK(watcher.send_line("get program_codes", in(kSecond)) == LineStatus::Ok);
  CHECK(watcher.read_line(line, in(kSecond)) == LineStatus::Ok);
  const std::string codes(line);
  STRCMP_CONTAINS("PROGRAM_CODES", codes.c_str());
  STRCMP_CONTAINS(" G61 ", codes.c_str());
  STRCMP_CONTAINS(" G21 ", codes.c_str());
  STRCMP_CONTAINS(" G90 ", codes.c_str());
  CHECK(codes.find(" G64 ") == std::string::npos);
}
