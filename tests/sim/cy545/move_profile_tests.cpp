// A CY545 move's step times against arithmetic done by hand: k/R rounded down without a ramp, and
// with one the manual's acceleration, a symmetric F -> R -> F trapezoid, a triangle when short.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "sim/cy545/move_profile.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using stencil::sim::cy545::MoveProfile;

namespace {
constexpr std::int64_t kNsPerSecond = 1'000'000'000;
}

TEST_GROUP(MoveProfile){};

TEST(MoveProfile, WithoutARampStepKIsAtKOverRRoundedDownAndTheMoveLastsNOverR) {
  const MoveProfile profile(3, 3, 1000, 0);
  CHECK_FALSE(profile.ramped());
  LONGS_EQUAL(333'333'333, profile.step_offset_ns(1));
  LONGS_EQUAL(666'666'666, profile.step_offset_ns(2));
  LONGS_EQUAL(kNsPerSecond, profile.duration_ns());
  LONGS_EQUAL(0, MoveProfile(0, 100, 100, 0).duration_ns());
}

TEST(MoveProfile, ASlopeRampsOnlyWhenTheFirstRateIsBelowTheSlewRate) {
  CHECK_TRUE(MoveProfile(100, 2000, 500, 10).ramped());
  CHECK_FALSE(MoveProfile(100, 2000, 2000, 10).ramped());
  CHECK_FALSE(MoveProfile(100, 2000, 500, 0).ramped());
}

TEST(MoveProfile, TheAccelerationIsTheManuals3906Times25Over256MinusS) {
  DOUBLES_EQUAL(3906.0 * 25.0 / 256.0, MoveProfile::acceleration_steps_per_s2(0), 1e-9);
  DOUBLES_EQUAL(3906.0 * 25.0, MoveProfile::acceleration_steps_per_s2(255), 1e-9);
}

TEST(MoveProfile, ALongRampedMoveStartsAtTheFirstRateCruisesAtTheSlewRateAndIsSymmetric) {
  // F = 500, R = 2000, S = 156: a = 976.5 steps/s^2, ramps of (2000^2 - 500^2) / (2 a) = 1920 steps.
  const std::uint32_t steps = 10'000;
  const MoveProfile profile(steps, 2000, 500, 156);
  const double a = 3906.0 * 25.0 / 100.0;
  // The first step: 1 = 500 t + a t^2 / 2.
  const double first_s = (std::sqrt(500.0 * 500.0 + 2.0 * a) - 500.0) / a;
  DOUBLES_EQUAL(first_s * 1e9, static_cast<double>(profile.step_offset_ns(1)), 1.0);
  // In the cruise each step is 1/R apart.
  LONGS_EQUAL(500'000, profile.step_offset_ns(5001) - profile.step_offset_ns(5000));
  // Decelerating mirrors accelerating.
  LONGS_EQUAL(profile.step_offset_ns(1), profile.duration_ns() - profile.step_offset_ns(steps - 1));
  const double ramp_s = (2000.0 - 500.0) / a;
  const double ramp_steps = (2000.0 * 2000.0 - 500.0 * 500.0) / (2.0 * a);
  DOUBLES_EQUAL((2.0 * ramp_s + (steps - 2.0 * ramp_steps) / 2000.0) * 1e9, static_cast<double>(profile.duration_ns()), 2.0);
}

TEST(MoveProfile, AShortRampedMoveIsATriangleThatNeverReachesTheSlewRate) {
  const MoveProfile profile(100, 2000, 500, 156);
  std::int64_t shortest = kNsPerSecond;
  for (std::uint32_t k = 1; k <= 100; ++k) {
    shortest = std::min(shortest, profile.step_offset_ns(k) - profile.step_offset_ns(k - 1));
  }
  CHECK_TRUE(shortest > 500'000);  // every step slower than 1/R
  LONGS_EQUAL(profile.duration_ns() / 2, profile.step_offset_ns(50));  // the peak in the middle
}
