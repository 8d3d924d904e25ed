// The virtual clock: moves only forward, only when slept on or advanced.
#include "sim/clock/virtual_clock.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

TEST_GROUP(VirtualClock){};

TEST(VirtualClock, SleepingJumpsToTheDeadlineAndNeverBack) {
  stencil::sim::VirtualClock clock(1000);
  CHECK_EQUAL(1000, clock.now_ns());
  clock.sleep_until_ns(5000);
  CHECK_EQUAL(5000, clock.now_ns());
  clock.sleep_until_ns(2000);  // already past
  CHECK_EQUAL(5000, clock.now_ns());
  clock.advance_ns(250);
  CHECK_EQUAL(5250, clock.now_ns());
  clock.advance_ns(-100);
  CHECK_EQUAL(5250, clock.now_ns());
}
