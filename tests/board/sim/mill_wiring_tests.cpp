// The simulation's machine (board/sim/mill_wiring): the CY545 driver on the fake chip's pty on
// virtual time, and what the machinist finds at the mill when the job ends (leave): a mill the driver
// stopped is off; one left running is switched off by the watchdog relay a second after its heartbeat
// stopped, and the result says so. A whole job's machining: e2e sim_raster_corner and the rest.
#include <string>

#include "board/sim/mill_wiring.hpp"
#include "board/sim/sim_job.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

constexpr hal::MonotonicNs kSecond = 1'000'000'000;

struct Machine {
  test::LoadedPart loaded{test::default_part(), 1};
  SimJob job;
  Machine() {
    job.part = &loaded.part;
    job.stock = default_stock(loaded.part);
  }
};

}  // namespace

TEST_GROUP(MillWiring){};

TEST(MillWiring, TheDriversPortOpensOnTheFakesPty) {
  Machine m;
  MillWiring mill(m.job, false);
  STRCMP_EQUAL("", mill.error().c_str());
  CHECK_TRUE(mill.fake().pty_open());
  CHECK_EQUAL(0, mill.clock().now_ns());  // virtual time starts at the epoch
}

TEST(MillWiring, AMillLeftRunningIsSwitchedOffByTheWatchdogRelay) {
  Machine m;
  MillWiring mill(m.job, false);
  CHECK_TRUE(mill.link().start(10 * kSecond).done);
  CHECK_TRUE(mill.link().set_spindle(true, mill.clock().now_ns() + kSecond).done);
  CHECK_TRUE(mill.mill().spindle_on());
  SimResult result;
  mill.leave(result, false, mill.clock().now_ns());
  CHECK_FALSE(result.machine_stop_confirmed);
  CHECK_TRUE(result.mill_spindle_on_after_stop);
  CHECK_TRUE(result.mill_relay_dropped_power);
  CHECK_FALSE(result.mill_on_after_relay);
}

TEST(MillWiring, AMillTheDriverStoppedIsFoundOff) {
  Machine m;
  MillWiring mill(m.job, false);
  CHECK_TRUE(mill.link().start(10 * kSecond).done);
  CHECK_TRUE(mill.link().set_spindle(true, mill.clock().now_ns() + kSecond).done);
  CHECK_TRUE(mill.link().stop(mill.clock().now_ns() + kSecond).done);
  SimResult result;
  mill.leave(result, true, mill.clock().now_ns());
  CHECK_TRUE(result.machine_stop_confirmed);
  CHECK_FALSE(result.mill_spindle_on_after_stop);
  CHECK_FALSE(result.mill_drivers_on_after_stop);
  CHECK_FALSE(result.mill_relay_dropped_power);  // nothing was on for it to drop
  CHECK_FALSE(result.mill_on_after_relay);
}
