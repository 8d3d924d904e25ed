// The fake clock's own tests (tests/fakes/fake_clock.hpp): set and advance move it only forward, a
// sleep jumps to its deadline (or stays when it has passed), every deadline is recorded in order, and
// the hook runs at the moment of waking, through the hal::Clock interface as the code under test sees it.
#include <vector>

#include "hal/clock.hpp"
#include "tests/fakes/fake_clock.hpp"

#include <CppUTest/TestHarness.h>

using stencil::hal::MonotonicNs;
using stencil::test::FakeClock;

TEST_GROUP(FakeClock){};

TEST(FakeClock, StartsWhereToldAndMovesOnlyForward) {
  FakeClock clock(1000);
  CHECK_EQUAL(1000, clock.now_ns());
  CHECK_TRUE(clock.advance_ns(500));
  CHECK_EQUAL(1500, clock.now_ns());
  CHECK_TRUE(clock.advance_ms(2));
  CHECK_EQUAL(2'001'500, clock.now_ns());
  CHECK_TRUE(clock.set_ns(3'000'000));
  CHECK_EQUAL(3'000'000, clock.now_ns());
  CHECK_TRUE(clock.set_ns(3'000'000));  // standing still is allowed
  CHECK_TRUE(clock.advance_ns(0));

  CHECK_FALSE(clock.set_ns(2'999'999));  // a Clock never goes back
  CHECK_FALSE(clock.advance_ns(-1));
  CHECK_EQUAL(3'000'000, clock.now_ns());
}

TEST(FakeClock, ASleepJumpsToItsDeadlineAndIsRecorded) {
  FakeClock clock(100);
  stencil::hal::Clock& as_seen = clock;
  as_seen.sleep_until_ns(250);
  CHECK_EQUAL(250, as_seen.now_ns());
  as_seen.sleep_until_ns(200);  // already past: no jump back, but the ask is still recorded
  CHECK_EQUAL(250, as_seen.now_ns());
  as_seen.sleep_until_ns(1000);
  const std::vector<MonotonicNs> expected{250, 200, 1000};
  CHECK_TRUE(expected == clock.sleeps());
}

TEST(FakeClock, TheHookRunsOnWakingWithTheTimeWokenAt) {
  FakeClock clock(0);
  std::vector<MonotonicNs> woken;
  clock.on_sleep = [&](MonotonicNs now_ns) {
    woken.push_back(now_ns);
    CHECK_EQUAL(now_ns, clock.now_ns());  // the clock has already moved when the hook runs
  };
  clock.sleep_until_ns(5);
  clock.sleep_until_ns(3);
  const std::vector<MonotonicNs> expected{5, 5};
  CHECK_TRUE(expected == woken);
  CHECK_TRUE(clock.advance_ns(10));
  CHECK_EQUAL(2U, woken.size());  // advancing is not sleeping
}
