// The rig's clock (hal/posix_clock/monotonic_clock.cpp) against CLOCK_MONOTONIC itself: now agrees
// with clock_gettime and never goes back, a deadline splits into the timespec the POSIX waits take,
// absolute sleeps wake no earlier than their deadline (at once when it has passed, or is 0 or below),
// and MonotonicClock is the same two calls behind hal::Clock. Sleeps here are a few milliseconds.
#include <ctime>

#include "hal/clock.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::MonotonicNs;
namespace posix_clock = hal::posix_clock;

namespace {

constexpr MonotonicNs kMs = 1'000'000;

MonotonicNs clock_gettime_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<MonotonicNs>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

}  // namespace

TEST_GROUP(MonotonicClock){};

TEST(MonotonicClock, NowIsClockMonotonicInNanoseconds) {
  const MonotonicNs before = clock_gettime_ns();
  const MonotonicNs now = posix_clock::monotonic_now_ns();
  const MonotonicNs after = clock_gettime_ns();
  CHECK_TRUE(before <= now);
  CHECK_TRUE(now <= after);
}

TEST(MonotonicClock, NowNeverGoesBack) {
  MonotonicNs previous = posix_clock::monotonic_now_ns();
  for (int read = 0; read < 10000; ++read) {
    const MonotonicNs now = posix_clock::monotonic_now_ns();
    CHECK_TRUE(now >= previous);
    previous = now;
  }
}

TEST(MonotonicClock, ADeadlineSplitsIntoSecondsAndNanoseconds) {
  const timespec zero = posix_clock::monotonic_timespec(0);
  CHECK_EQUAL(0, zero.tv_sec);
  CHECK_EQUAL(0L, zero.tv_nsec);
  const timespec one_and_a_half = posix_clock::monotonic_timespec(1'500'000'000);
  CHECK_EQUAL(1, one_and_a_half.tv_sec);
  CHECK_EQUAL(500'000'000L, one_and_a_half.tv_nsec);
  const timespec just_under = posix_clock::monotonic_timespec(86'400'999'999'999);
  CHECK_EQUAL(86'400, just_under.tv_sec);
  CHECK_EQUAL(999'999'999L, just_under.tv_nsec);
}

TEST(MonotonicClock, ASleepWakesNoEarlierThanItsDeadline) {
  const MonotonicNs deadline = posix_clock::monotonic_now_ns() + 3 * kMs;
  posix_clock::sleep_until_monotonic_ns(deadline);
  const MonotonicNs woke = posix_clock::monotonic_now_ns();
  CHECK_TRUE(woke >= deadline);
  CHECK_TRUE(woke < deadline + 1000 * kMs);  // absolute, not a duration added to something late
}

TEST(MonotonicClock, ADeadlineThatHasPassedReturnsAtOnce) {
  const MonotonicNs start = posix_clock::monotonic_now_ns();
  posix_clock::sleep_until_monotonic_ns(start - 10 * kMs);
  posix_clock::sleep_until_monotonic_ns(0);
  posix_clock::sleep_until_monotonic_ns(-1);
  CHECK_TRUE(posix_clock::monotonic_now_ns() - start < 5 * kMs);
}

TEST(MonotonicClock, TheClockBehindTheInterfaceIsTheSameClock) {
  posix_clock::MonotonicClock monotonic;
  hal::Clock& clock = monotonic;
  const MonotonicNs before = posix_clock::monotonic_now_ns();
  const MonotonicNs now = clock.now_ns();
  CHECK_TRUE(now >= before);
  CHECK_TRUE(now <= posix_clock::monotonic_now_ns());
  const MonotonicNs deadline = now + 2 * kMs;
  clock.sleep_until_ns(deadline);
  CHECK_TRUE(clock.now_ns() >= deadline);
}
