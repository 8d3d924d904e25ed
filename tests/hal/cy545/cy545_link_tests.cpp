// The CY545 driver against the simulated CY545 on a real pseudo-terminal (wall time), against a
// scripted peer that only records bytes, and against faults: no answer, garbage, a wrong position,
// the port closed, a path that is not a tty.
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <atomic>
#include <cstring>
#include <mutex>
#include <thread>

#include "board/sim/sim_facts.hpp"
#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_clock.hpp"
#include "sim/cy545/fake_cy545_runner.hpp"
#include "sim/mill/simulated_mill.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::hal;
using namespace stencil::hal::cy545;
using stencil::sim::Axis;
using stencil::sim::StepDirection;

namespace {

constexpr MonotonicNs kMs = 1'000'000;
constexpr std::uint32_t kBaud = stencil::board::sim::kBaud;  // the rig's line, as the simulation runs it

Cy545Config fast_homing_config() {
  Cy545Config config = stencil::board::sherline_suzuki::kCy545;
  config.motion.homing_rate = 20000;        // quick in tests
  config.motion.homing_slow_rate = 5000;
  config.motion.homing_travel_steps = 2000;  // the test puts every axis within 200 steps of its switch
  // The fake is a thread on a host that is not real-time, and CI runs it under the sanitizers beside
  // other tests: a second (250 ms was once missed there, ASan at a load of 6 on 2 cores).
  config.reply_timeout_ns = 1000 * kMs;
  return config;
}

// The simulated mill with every axis a little above its home switch, the fake CY545 on a pty
// serviced in real time, and the driver on the pty's other end.
struct Bench {
  sim::SimulatedMill mill{stencil::board::sim::kMillConfig};
  bool placed = place_near_home(mill);
  sim::cy545::FakeCy545 fake{mill, stencil::board::sim::kMmc4sWiring, hal::posix_clock::monotonic_now_ns()};
  posix_clock::MonotonicClock clock;
  SerialPort port;
  bool opened = open(port, fake.slave_path());
  Cy545Link link;
  sim::cy545::FakeCy545Runner runner{fake};

  explicit Bench(const Cy545Config& config = fast_homing_config()) : link(port, clock, config) {}

  static bool place_near_home(sim::SimulatedMill& mill) {
    mill.place_axis(Axis::x, 150, StepDirection::positive);
    mill.place_axis(Axis::y, 60, StepDirection::positive);
    mill.place_axis(Axis::z, 190, StepDirection::positive);
    return true;
  }
  static bool open(SerialPort& port, const std::string& path) {
    char error[256] = {};
    CHECK_TEXT(port.open(path.c_str(), kBaud, error), error);
    return true;
  }
  MonotonicNs in(MonotonicNs ns) const { return clock.now_ns() + ns; }
  std::int64_t motor(Axis axis) {
    return runner.with_fake([&](sim::cy545::FakeCy545&) { return mill.motor_position_steps(axis); });
  }
  std::int64_t axis(Axis a) {
    return runner.with_fake([&](sim::cy545::FakeCy545&) { return mill.axis_position_steps(a); });
  }
  void start_and_home() {
    const MachineResult started = link.start(in(2000 * kMs));
    CHECK_TEXT(started.done, link.last_error());
    const MachineResult homed = link.home(in(link.homing_bound_ns() + 1000 * kMs));
    CHECK_TEXT(homed.done, link.last_error());
  }
};

MachineTarget target(std::int32_t x, std::int32_t y, std::int32_t z, std::array<std::uint8_t, 3> order = {0, 1, 2},
                     bool cutting = true) {
  return {{x, y, z}, order, cutting};
}

}  // namespace

TEST_GROUP(Cy545Link){};

TEST(Cy545Link, StartsHomesEveryAxisOnItsSwitchAndMovesTheMotorsByExactSteps) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.status().state == MachineState::Homed);
  // Homing ends at the switch edge, the last steps upward: every axis at 0.
  CHECK_EQUAL(0, bench.axis(Axis::x));
  CHECK_EQUAL(0, bench.axis(Axis::y));
  CHECK_EQUAL(0, bench.axis(Axis::z));
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  // The motors stand a backlash above their axes after homing's last, upward steps.
  const std::int64_t home_x = bench.motor(Axis::x), home_y = bench.motor(Axis::y), home_z = bench.motor(Axis::z);
  const MachineTarget path[] = {target(10, 12, 8), target(25, 4, 8, {1, 0, 2}), target(25, 4, -3, {2, 1, 0}),
                                target(13, 20, -3, {1, 0, 2}), target(13, 20, 10)};
  for (const MachineTarget& t : path) {
    const MachineResult moved = bench.link.move(t, bench.in(500 * kMs));
    CHECK_TEXT(moved.done, bench.link.last_error());
  }
  CHECK_EQUAL(13, bench.motor(Axis::x) - home_x);
  CHECK_EQUAL(20, bench.motor(Axis::y) - home_y);
  CHECK_EQUAL(10, bench.motor(Axis::z) - home_z);
  const MachineResult verified = bench.link.verify(bench.in(200 * kMs));
  CHECK_TEXT(verified.done, bench.link.last_error());
  CHECK_EQUAL(5U, bench.link.status().moves_done);
  CHECK(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.spindle_on(); }));
}

TEST(Cy545Link, RefusesWhatItMustNotDoAndSendsNothingForIt) {
  Bench bench;
  CHECK(bench.link.move(target(1, 0, 0), bench.in(200 * kMs)).refusal == MachineRefusal::NotHomed);
  bench.start_and_home();
  CHECK(bench.link.move(target(1, 0, 0), bench.in(200 * kMs)).refusal == MachineRefusal::SpindleOff);
  const std::int64_t home_x = bench.motor(Axis::x);
  CHECK(bench.link.move(target(1, 0, 0, {0, 1, 2}, false), bench.in(200 * kMs)).done);  // not cutting: allowed
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  CHECK(bench.link.move(target(1, 0, 0, {0, 0, 2}), bench.in(200 * kMs)).refusal == MachineRefusal::BadTarget);
  CHECK(bench.link.move(target(60, 0, 0), bench.in(200 * kMs)).refusal == MachineRefusal::TooLong);
  CHECK(bench.link.move(target(20, 0, 0), bench.in(5 * kMs)).refusal == MachineRefusal::DeadlineTooShort);
  bench.link.hold();
  CHECK(bench.link.move(target(2, 0, 0), bench.in(200 * kMs)).refusal == MachineRefusal::Held);
  bench.link.resume();
  CHECK(bench.link.move(target(2, 0, 0), bench.in(200 * kMs)).done);
  CHECK_EQUAL(2, bench.motor(Axis::x) - home_x);
}

TEST(Cy545Link, StopTurnsSpindleAndDriversOffAndWantsHomingAgain) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  CHECK(bench.link.stop(bench.in(200 * kMs)).done);
  // Give the fake a moment to read the last bytes.
  usleep(20000);
  CHECK_FALSE(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.drivers_enabled(); }));
  CHECK_FALSE(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.spindle_on(); }));
  CHECK(bench.link.status().state == MachineState::Stopped);
  CHECK(bench.link.move(target(1, 0, 0, {0, 1, 2}, false), bench.in(200 * kMs)).refusal == MachineRefusal::NotHomed);
}

TEST(Cy545Link, AReplyThatNeverComesIsATimeoutFaultWithinItsBound) {
  Bench bench;
  bench.start_and_home();
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.set_replies_suppressed(true);
    return 0;
  });
  const auto before = std::chrono::steady_clock::now();
  const MachineResult verified = bench.link.verify(bench.in(5000 * kMs));
  const double waited_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - before).count();
  CHECK(verified.fault == MachineFault::Timeout);
  CHECK(waited_ms < 2500.0);  // the reply bound (1 s), not the caller's 5 s
  CHECK(bench.link.status().state == MachineState::Fault);
  CHECK(bench.link.move(target(1, 0, 0, {0, 1, 2}, false), bench.in(200 * kMs)).refusal == MachineRefusal::Faulted);
}

TEST(Cy545Link, GarbageInAReplyIsAFaultNamingTheByte) {
  Bench bench;
  bench.start_and_home();
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.set_replies_garbled(true);
    return 0;
  });
  CHECK(bench.link.verify(bench.in(500 * kMs)).fault == MachineFault::GarbledReply);
  STRCMP_CONTAINS("byte 0", bench.link.last_error());
}

TEST(Cy545Link, APositionOtherThanTheCommandedOneIsAFault) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.move(target(5, 0, 0, {0, 1, 2}, false), bench.in(200 * kMs)).done);
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.set_reported_position_offset(3);
    return 0;
  });
  CHECK(bench.link.verify(bench.in(500 * kMs)).fault == MachineFault::PositionMismatch);
  STRCMP_CONTAINS("5 was commanded", bench.link.last_error());
}

TEST(Cy545Link, APortClosedMidJobIsAFault) {
  Bench bench;
  bench.start_and_home();
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.close_pty();
    return 0;
  });
  const MachineResult verified = bench.link.verify(bench.in(500 * kMs));
  CHECK(verified.fault == MachineFault::PortClosed);
  CHECK(bench.link.status().fault == MachineFault::PortClosed);
}

TEST(Cy545Link, StartUpGivesUpWhenTheControllerNeverAnswers) {
  Cy545Config config = fast_homing_config();
  config.start_attempts = 5;
  Bench bench(config);
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.set_replies_suppressed(true);
    return 0;
  });
  const MachineResult started = bench.link.start(bench.in(2000 * kMs));
  CHECK(started.fault == MachineFault::NoAnswer);
  STRCMP_CONTAINS("never answered", bench.link.last_error());
}

TEST(Cy545Link, APathThatIsNotASerialPortIsRefusedByName) {
  SerialPort port;
  char error[256] = {};
  CHECK_FALSE(port.open("/dev/null", kBaud, error));
  STRCMP_CONTAINS("/dev/null: not a serial port", error);
  char file[] = "/tmp/stencil-not-a-tty-XXXXXX";
  const int fd = mkstemp(file);
  CHECK(fd >= 0);
  close(fd);
  CHECK_FALSE(port.open(file, kBaud, error));
  STRCMP_CONTAINS("not a serial port", error);
  unlink(file);
  CHECK_FALSE(port.open("/dev/no-such-port", kBaud, error));
  STRCMP_CONTAINS("/dev/no-such-port: cannot open", error);
}

TEST(Cy545Link, OneUpdateIsExactlyTheseBytes) {
  // A scripted peer: a pty whose master records what the driver writes and answers each "? P"
  // with the next scripted position.
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  CHECK(master >= 0);
  CHECK(grantpt(master) == 0 && unlockpt(master) == 0);
  SerialPort port;
  char error[256] = {};
  CHECK_TEXT(port.open(ptsname(master), kBaud, error), error);
  CHECK_FALSE(port.has_modem_lines());
  posix_clock::MonotonicClock clock;
  Cy545Link link(port, clock, stencil::board::sherline_suzuki::kCy545);
  CHECK(link.declare_home(clock.now_ns() + 100 * kMs).refusal == MachineRefusal::NotHomed);  // not started
  std::string recorded;
  std::mutex recorded_mutex;
  std::atomic<bool> done{false};
  // Start-up, then after the legs z +2, x +5, y -3 and x +4 the register holds 2, 7, 4, 8.
  std::thread peer([&]() {
    const char* replies[] = {"P=0\r", "P=2\r", "P=7\r", "P=4\r", "P=8\r"};
    std::size_t answered = 0;
    std::size_t seen = 0;  // where in the whole stream the last answered query ended
    std::string stream;    // everything, never cleared (take() clears `recorded`)
    char buffer[256];
    while (!done) {
      pollfd request{master, POLLIN, 0};
      if (poll(&request, 1, 10) <= 0) {
        continue;
      }
      const ssize_t n = read(master, buffer, sizeof buffer);
      if (n <= 0) {
        break;
      }
      const std::lock_guard<std::mutex> lock(recorded_mutex);
      recorded.append(buffer, static_cast<std::size_t>(n));
      stream.append(buffer, static_cast<std::size_t>(n));
      // "? B" (the outputs, read back after the drivers-off commands) reads all low but CTS.
      for (;;) {
        const std::size_t position_query = stream.find("? P\r", seen);
        const std::size_t bits_query = stream.find("? B\r", seen);
        if (bits_query < position_query) {
          seen = bits_query + 4;
          CHECK(write(master, "B=64\r", 5) > 0);
        } else if (position_query != std::string::npos && answered < 5) {
          seen = position_query + 4;
          CHECK(write(master, replies[answered], std::strlen(replies[answered])) > 0);
          ++answered;
        } else {
          break;
        }
      }
    }
  });
  const auto take = [&]() {
    usleep(20000);
    const std::lock_guard<std::mutex> lock(recorded_mutex);
    std::string got;
    got.swap(recorded);
    // Surplus carriage returns while the chip may still be busy are empty lines: no effect.
    std::string collapsed;
    for (const char c : got) {
      if (!(c == '\r' && !collapsed.empty() && collapsed.back() == '\r')) {
        collapsed.push_back(c);
      }
    }
    return collapsed;
  };
  const MachineResult started = link.start(clock.now_ns() + 1000 * kMs);
  CHECK_TEXT(started.done, link.last_error());
  CHECK(link.declare_home(clock.now_ns() + 100 * kMs).done);
  // Wake, initialise in ASCII mode, every motor channel's line latched off (data 0 at addresses 0-3,
  // drivers off), then the outputs off (spindle output 4, strobed; every bit low) and read back, then
  // home declared.
  STRCMP_EQUAL("\r? P\rI\rO 128\rR 1000\rF 1000\rS 0\r"
               "B 40H\rB 7H\r/B 7\rB 44H\rB 7H\r/B 7\rB 48H\rB 7H\r/B 7\rB 4CH\rB 7H\r/B 7\r"
               "? B\rB 50H\rB 7H\r/B 7\rB 40H\r? B\rA 0\r",
               take().c_str());
  MachineResult moved = link.move(target(5, -3, 2, {2, 0, 1}, false), clock.now_ns() + 500 * kMs);
  CHECK_TEXT(moved.done, link.last_error());
  STRCMP_EQUAL(
      "B 4BH\rB 7H\r/B 7\rN 2\r+\rG\r? P\r"                    // z first: channel 2's line on, 2 steps up, done?
      "B 49H\rB 7H\r/B 7\rB 43H\rB 7H\r/B 7\rN 5\r+\rG\r? P\r"   // then x: z's line off, channel 0's on, 5 up
      "B 41H\rB 7H\r/B 7\rB 47H\rB 7H\r/B 7\rN 3\r-\rG\r? P\r",  // then y: x's off, channel 1's on, 3 down
      take().c_str());
  moved = link.move(target(9, -3, 2, {0, 1, 2}, false), clock.now_ns() + 500 * kMs);
  CHECK_TEXT(moved.done, link.last_error());
  STRCMP_EQUAL("B 45H\rB 7H\r/B 7\rB 43H\rB 7H\r/B 7\rN 4\r+\rG\r? P\r", take().c_str());  // x again
  done = true;
  peer.join();
  close(master);
}

TEST(Cy545Link, MeasuresTheLinksThroughputAgainstTheFake) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  const std::uint64_t bytes_before = bench.link.status().bytes_sent;
  const int updates = 60;
  const auto begin = std::chrono::steady_clock::now();
  for (int i = 1; i <= updates; ++i) {
    // A diagonal move at the mill's full rate: 11 steps on each axis, 33 in all (one update's worth).
    const std::int32_t s = (i % 2) * 11;
    const MachineResult moved = bench.link.move(target(s, s, s), bench.in(500 * kMs));
    CHECK_TEXT(moved.done, bench.link.last_error());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const double bytes_per_update = static_cast<double>(bench.link.status().bytes_sent - bytes_before) / updates;
  std::printf("\n  CY545 link against the fake: %.1f updates/s, %.1f bytes per update (3 axes, 33 steps)\n",
              updates / seconds, bytes_per_update);
  CHECK(bench.link.verify(bench.in(200 * kMs)).done);
}

// Issue 18, item 2: "O 0" put the real chip into binary mode; the driver now says ASCII explicitly.
TEST(Cy545Link, StartLeavesTheChipInAsciiMode) {
  Bench bench;
  bench.start_and_home();
  CHECK_EQUAL(0x80U, bench.runner.with_fake([](sim::cy545::FakeCy545& fake) { return fake.chip().mode(); }));
}

// Issue 18, item 1: the MMC-4S's latches keep the spindle on across a program's restart (and the
// chip's "I"): the next start must turn it off before anything else.
TEST(Cy545Link, StartTurnsOffASpindleThatAnEarlierRunLeftOn) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  // The program dies here (no stop); a new one opens the same port.
  Cy545Link restarted(bench.port, bench.clock, fast_homing_config());
  CHECK_TEXT(restarted.start(bench.in(2000 * kMs)).done, restarted.last_error());
  CHECK_FALSE(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.spindle_on(); }));
  CHECK_FALSE(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.drivers_enabled(); }));
  CHECK_FALSE(restarted.status().spindle_on);
}

// Issue 18, item 1: a latched fault (here a garbled reply) used to make stop() refuse before it sent
// anything, leaving the spindle turning while the terminal said the mill was stopped.
TEST(Cy545Link, StopTurnsSpindleAndDriversOffEvenWithAFaultLatched) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.set_replies_garbled(true);
    return 0;
  });
  CHECK(bench.link.verify(bench.in(500 * kMs)).fault == MachineFault::GarbledReply);
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.set_replies_garbled(false);  // the line recovers; the latch stays
    return 0;
  });
  const MachineResult stopped = bench.link.stop(bench.in(2000 * kMs));
  CHECK_TEXT(stopped.done, bench.link.last_error());
  CHECK(bench.link.outputs_confirmed_off());
  CHECK_FALSE(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.spindle_on(); }));
  CHECK_FALSE(bench.runner.with_fake([&](sim::cy545::FakeCy545&) { return bench.mill.drivers_enabled(); }));
  CHECK(bench.link.status().fault == MachineFault::GarbledReply);  // the reason stays reported
}

// Issue 18, item 1: a stop that cannot reach the chip says so, instead of claiming the mill stopped.
TEST(Cy545Link, AStopThatCannotReachTheControllerSaysTheSpindleMayStillBeOn) {
  Bench bench;
  bench.start_and_home();
  CHECK(bench.link.set_spindle(true, bench.in(200 * kMs)).done);
  bench.runner.with_fake([](sim::cy545::FakeCy545& fake) {
    fake.close_pty();
    return 0;
  });
  const MachineResult stopped = bench.link.stop(bench.in(500 * kMs));
  CHECK_FALSE(stopped.done);
  CHECK_FALSE(bench.link.outputs_confirmed_off());
  STRCMP_CONTAINS("may still be on", bench.link.last_error());
}

namespace {

// The same chain on virtual time (the fast simulation's FakeCy545Clock): deterministic, and a
// homing of tens of seconds takes a fraction of one here.
struct VirtualBench {
  sim::SimulatedMill mill{stencil::board::sim::kMillConfig};  // every axis mid-travel, as at power-up
  sim::cy545::FakeCy545 fake{mill, stencil::board::sim::kMmc4sWiring, 0};
  sim::cy545::FakeCy545Clock clock{fake, 0, kBaud};
  SerialPort port;
  bool opened = Bench::open(port, fake.slave_path());
  Cy545Link link;

  explicit VirtualBench(const Cy545Config& config = stencil::board::sherline_suzuki::kCy545) : link(port, clock, config) {}

  // As the rig does: wake-up and spindle in seconds, homing as long as the link says it can take.
  MachineResult start_and_home() {
    const MachineResult started = link.start(clock.now_ns() + 20'000 * kMs);
    if (!started.done) {
      return started;
    }
    return link.home(clock.now_ns() + link.homing_bound_ns() + 20'000 * kMs);
  }
};

}  // namespace

// Issue 18, item 3: with the shipped defaults the old home() needed three seeks of 41 s plus margins
// (123.1 s) within the rig's 120 s and always refused; now the deadline follows the travel.
TEST(Cy545Link, ShippedDefaultsHomeFromPowerUpWithinTheDeadlineTheRigGives) {
  VirtualBench bench;
  const MonotonicNs began = bench.clock.now_ns();
  const MachineResult homed = bench.start_and_home();
  CHECK_TEXT(homed.done, bench.link.last_error());
  CHECK_EQUAL(0, bench.mill.axis_position_steps(Axis::x));
  CHECK_EQUAL(0, bench.mill.axis_position_steps(Axis::y));
  CHECK_EQUAL(0, bench.mill.axis_position_steps(Axis::z));
  std::printf("\n  homing from mid-travel with the shipped defaults: %.1f s (bound %.0f s)\n",
              static_cast<double>(bench.clock.now_ns() - began) / 1e9,
              static_cast<double>(bench.link.homing_bound_ns()) / 1e9);
}

// Issue 18, item 3: inverted switch wiring made the chip's H command seek the wrong way (Z down into
// the work, on and on). Now a switch that still reads closed a zone's depth out is a fault, and the
// axis has moved no further than that.
TEST(Cy545Link, InvertedHomeSwitchWiringIsAFaultAfterAtMostTheSwitchZone) {
  VirtualBench bench;
  bench.fake.board().set_home_switches_inverted(true);
  const std::int64_t z_before = bench.mill.axis_position_steps(Axis::z);
  const MachineResult homed = bench.start_and_home();
  CHECK_FALSE(homed.done);
  CHECK(homed.fault == MachineFault::PositionMismatch);
  STRCMP_CONTAINS("homing axis Z: its home switch still reads closed", bench.link.last_error());
  const Cy545Config defaults = stencil::board::sherline_suzuki::kCy545;
  CHECK(bench.mill.axis_position_steps(Axis::z) - z_before <= defaults.motion.home_switch_zone_steps + defaults.motion.homing_chunk_steps);
  CHECK_EQUAL(0, bench.mill.axis_position_steps(Axis::x) - stencil::board::sim::kMillConfig.axes[0].initial_position_steps);
}

TEST(Cy545Link, TheConfiguredClosedLevelHomesInvertedWiring) {
  Cy545Config config = stencil::board::sherline_suzuki::kCy545;
  config.wiring.home_switch_closed_level = {false, false, false};
  VirtualBench bench(config);
  bench.fake.board().set_home_switches_inverted(true);
  CHECK_TEXT(bench.start_and_home().done, bench.link.last_error());
  CHECK_EQUAL(0, bench.mill.axis_position_steps(Axis::z));
}

// Issue 18, item 9: a switch that chatters near its edge. The slow, debounced departure finds the
// edge within the chatter's band; that band is the repeatability of home, and so of --resume.
TEST(Cy545Link, ABouncingHomeSwitchHomesWithinItsBandAndTheSpreadIsReported) {
  constexpr std::int64_t kBand = 6;  // steps either side of the edge (about 10 um)
  std::int64_t lowest = 1 << 20, highest = -(1 << 20);
  for (int run = 0; run < 8; ++run) {
    VirtualBench bench;
    bench.fake.board().set_home_switch_bounce(kBand);
    for (int skip = 0; skip < run * 7; ++skip) {  // another stretch of the chatter's sequence each run
      static_cast<void>(bench.fake.board().input_level(2));
    }
    bench.mill.place_axis(Axis::z, 300 + 37 * run, sim::StepDirection::positive);
    CHECK_TEXT(bench.start_and_home().done, bench.link.last_error());
    const std::int64_t z = bench.mill.axis_position_steps(Axis::z);
    lowest = std::min(lowest, z);
    highest = std::max(highest, z);
  }
  CHECK(lowest >= -kBand && highest <= kBand);
  std::printf("\n  home with a switch chattering +-%lld steps: Z homed within [%lld, %lld] steps of the edge, a spread of %lld "
              "steps (%.1f um)\n",
              static_cast<long long>(kBand), static_cast<long long>(lowest), static_cast<long long>(highest),
              static_cast<long long>(highest - lowest), static_cast<double>(highest - lowest) / 0.64);
}

// Issue 18, item 4: Ctrl-C while homing was read by nobody until the cut began. A stop asked for now
// ends homing at once, outputs off.
TEST(Cy545Link, AStopAskedWhileHomingEndsItBeforeTheNextLegWithTheOutputsOff) {
  VirtualBench bench;
  std::atomic<bool> stop{false};
  bench.link.abort_on(&stop);
  CHECK(bench.link.start(bench.clock.now_ns() + 20'000 * kMs).done);
  stop.store(true);
  const std::int64_t z_before = bench.mill.axis_position_steps(Axis::z);
  const MachineResult homed = bench.link.home(bench.clock.now_ns() + bench.link.homing_bound_ns() + 20'000 * kMs);
  CHECK(homed.refusal == MachineRefusal::Aborted);
  STRCMP_CONTAINS("homing stopped as asked; spindle and drivers off", bench.link.last_error());
  CHECK(bench.mill.axis_position_steps(Axis::z) - z_before == 0);
  CHECK_FALSE(bench.mill.drivers_enabled());
  CHECK_FALSE(bench.link.status().homed);
}

// Issue 18, item 8: a board whose channel lines each latch their data bit. The old driver selected
// with the data bit 0 and never deselected: here that selects nothing (or, once a line is on, leaves
// it on beside the next), so the mill's axes do not follow the chip's one position register.
TEST(Cy545Link, OnABoardThatLatchesEachChannelLineOnlyTheAxisCommandedMoves) {
  VirtualBench bench;  // the fake's default board: PerLine
  bench.mill.place_axis(Axis::x, 150, sim::StepDirection::positive);
  bench.mill.place_axis(Axis::y, 60, sim::StepDirection::positive);
  bench.mill.place_axis(Axis::z, 190, sim::StepDirection::positive);
  CHECK_TEXT(bench.start_and_home().done, bench.link.last_error());
  const MachineTarget path[] = {target(20, 0, 0, {0, 1, 2}, false), target(20, 15, 0, {1, 0, 2}, false),
                                target(20, 15, 20, {2, 1, 0}, false), target(10, 5, 20, {0, 1, 2}, false)};
  for (const MachineTarget& t : path) {
    CHECK_TEXT(bench.link.move(t, bench.clock.now_ns() + 500 * kMs).done, bench.link.last_error());
  }
  CHECK_EQUAL(1, bench.fake.board().selected_channel_count());
  // Homing's last steps were up; the last move's 10 steps back on x and y only take up their slack
  // (80 and 32 steps), so every axis stands where its up-moves took it, and each only by its own.
  CHECK_EQUAL(20, bench.mill.axis_position_steps(Axis::x));
  CHECK_EQUAL(15, bench.mill.axis_position_steps(Axis::y));
  CHECK_EQUAL(20, bench.mill.axis_position_steps(Axis::z));
}

// Issue 18, item 7: the same driver with no settle between commands (as before) loses bytes in the
// chip's three-character buffer on virtual time, where bytes take their wire time and commands the
// chip's: start-up's commands already arrive while the chip still takes the one before.
TEST(Cy545Link, WithoutTheSettleBetweenCommandsTheChipLosesBytes) {
  Cy545Config config = stencil::board::sherline_suzuki::kCy545;
  config.command_settle_ns = 0;
  VirtualBench bench(config);
  const MachineResult started = bench.link.start(bench.clock.now_ns() + 300 * kMs);
  VirtualBench paced;
  CHECK_TEXT(paced.link.start(paced.clock.now_ns() + 2'000 * kMs).done, paced.link.last_error());
  std::printf("\n  start-up on virtual time: %lld bytes lost without the settle (started: %s, %lld malformed lines), %lld "
              "with it (surplus carriage returns of a query's wait)\n",
              static_cast<long long>(bench.fake.chip().counters().bytes_dropped_while_busy), started.done ? "yes" : "no",
              static_cast<long long>(bench.fake.chip().counters().malformed_lines),
              static_cast<long long>(paced.fake.chip().counters().bytes_dropped_while_busy));
  LONGS_EQUAL(0, paced.fake.chip().counters().malformed_lines);
  CHECK(bench.fake.chip().counters().malformed_lines > 0 || !started.done);
}

// Issue 18, item 1: no software survives SIGKILL or a power cut; the rig's hardware watchdog (a
// relay in the spindle's and drivers' power) drops when the heartbeat output stops changing. The
// driver beats it at every update and through homing; a process that stops beating leaves the mill
// without power within the relay's time.
TEST(Cy545Link, TheWatchdogRelayStaysClosedWhileTheDriverBeatsAndDropsWhenItStops) {
  VirtualBench bench;
  bench.fake.board().arm_watchdog_relay(5, 1'000 * kMs, bench.clock.now_ns());
  CHECK_TEXT(bench.start_and_home().done, bench.link.last_error());  // homing from mid-travel: about 45 s
  CHECK(bench.fake.board().watchdog_relay_closed());
  CHECK(bench.link.set_spindle(true, bench.clock.now_ns() + 200 * kMs).done);
  for (int update = 0; update < 90; ++update) {  // three seconds of updates
    CHECK(bench.link.keep_alive(bench.clock.now_ns() + 60 * kMs).done);
    bench.clock.sleep_until_ns(bench.clock.now_ns() + 33 * kMs);
  }
  CHECK(bench.fake.board().watchdog_relay_closed());
  CHECK(bench.mill.spindle_on());
  // The process is killed: nothing more is sent.
  bench.fake.step(bench.clock.now_ns() + 1'500 * kMs);
  CHECK_FALSE(bench.fake.board().watchdog_relay_closed());
  CHECK_FALSE(bench.mill.spindle_on());
  CHECK_FALSE(bench.mill.drivers_enabled());
}
