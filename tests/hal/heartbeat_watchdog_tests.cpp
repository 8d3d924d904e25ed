// HeartbeatWatchdog (hal/heartbeat_watchdog.hpp) alone: when a counter the other side increments counts
// as stopped. Both haptic backends and the simulated device lean on exactly these edges (the timeout is
// inclusive; the first observation starts the clock; any change, a wrap included, is a beat).
#include <cstdint>

#include "hal/heartbeat_watchdog.hpp"

#include <CppUTest/TestHarness.h>

using stencil::hal::HeartbeatWatchdog;
using stencil::hal::MonotonicNs;

namespace {

constexpr MonotonicNs kTimeoutNs = 50;

// Usable at compile time, as the backends' constexpr constructors need.
constexpr bool expires_after_the_timeout() {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  static_cast<void>(watchdog.observe(1U, 0));
  return watchdog.observe(1U, kTimeoutNs) && !watchdog.observe(1U, kTimeoutNs + 1);
}
static_assert(expires_after_the_timeout());

}  // namespace

TEST_GROUP(HeartbeatWatchdog){};

TEST(HeartbeatWatchdog, IsNotExpiredBeforeItHasSeenAnything) {
  const HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_FALSE(watchdog.expired(0));
  CHECK_FALSE(watchdog.expired(1'000'000'000'000));
  CHECK_EQUAL(kTimeoutNs, watchdog.timeout_ns());
}

TEST(HeartbeatWatchdog, TheFirstObservationStartsTheClockWhateverItsValue) {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_TRUE(watchdog.observe(0U, 1000));  // zero is a heartbeat like any other
  CHECK_TRUE(watchdog.observe(0U, 1000 + kTimeoutNs));
  CHECK_FALSE(watchdog.observe(0U, 1000 + kTimeoutNs + 1));
  CHECK_TRUE(watchdog.expired(1000 + kTimeoutNs + 1));
}

TEST(HeartbeatWatchdog, AHeartbeatThatStaysIsAliveUpToTheTimeoutAndStoppedOneNanosecondAfter) {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_TRUE(watchdog.observe(7U, 100));
  for (MonotonicNs now = 100; now <= 100 + kTimeoutNs; now += 5) {
    CHECK_TRUE(watchdog.observe(7U, now));
    CHECK_FALSE(watchdog.expired(now));
  }
  CHECK_FALSE(watchdog.observe(7U, 100 + kTimeoutNs + 1));
  CHECK_TRUE(watchdog.expired(100 + kTimeoutNs + 1));
}

TEST(HeartbeatWatchdog, EveryChangeRestartsTheTimeoutEvenAfterItExpired) {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_TRUE(watchdog.observe(1U, 0));
  CHECK_TRUE(watchdog.observe(2U, 40));
  CHECK_TRUE(watchdog.observe(2U, 40 + kTimeoutNs));  // timed from the change at 40, not from 0
  CHECK_FALSE(watchdog.observe(2U, 200));
  CHECK_TRUE(watchdog.observe(3U, 300));  // beating again: alive at once
  CHECK_FALSE(watchdog.expired(300 + kTimeoutNs));
}

TEST(HeartbeatWatchdog, AChangeBackwardsOrAcrossTheWrapIsABeat) {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_TRUE(watchdog.observe(0xFFFFFFFFU, 0));
  CHECK_TRUE(watchdog.observe(0U, 40));
  CHECK_TRUE(watchdog.observe(0U, 40 + kTimeoutNs));
  CHECK_TRUE(watchdog.observe(5U, 80));  // a restarted peer counts from low again
  CHECK_TRUE(watchdog.observe(1U, 120));
  CHECK_FALSE(watchdog.expired(120 + kTimeoutNs));
}

TEST(HeartbeatWatchdog, ExpiredOnlyLooksAndNeverStartsTheClock) {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_FALSE(watchdog.expired(10));
  CHECK_TRUE(watchdog.observe(4U, 1000));  // the clock starts here, not at the look at 10
  CHECK_FALSE(watchdog.expired(1000 + kTimeoutNs));
}

TEST(HeartbeatWatchdog, RestartForgetsTheHistorySoTheNextObservationStartsAgain) {
  HeartbeatWatchdog watchdog(kTimeoutNs);
  CHECK_TRUE(watchdog.observe(9U, 0));
  CHECK_FALSE(watchdog.observe(9U, 1000));
  watchdog.restart();
  CHECK_FALSE(watchdog.expired(1000));
  CHECK_TRUE(watchdog.observe(9U, 1000));  // the same value: a fresh start, not a frozen beat
  CHECK_TRUE(watchdog.observe(9U, 1000 + kTimeoutNs));
  CHECK_FALSE(watchdog.observe(9U, 1000 + kTimeoutNs + 1));
}
