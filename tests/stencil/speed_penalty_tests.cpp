// Penalty-based speed limiting's law (stencil/speed_penalty.hpp): nothing below an onset, then a
// damper's force at a bounded slope against the hand's velocity, at most the force limit.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/speed_penalty.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::engine;

namespace {

constexpr double kLimit = 0.01;  // the rig's mill at the device: 1 world mm/s x 10, in m/s
constexpr double kForceLimit = 5.0;
constexpr double kSlope = 350.0;

}  // namespace

TEST_GROUP(SpeedPenalty){};

TEST(SpeedPenalty, NothingBelowATenthOfTheLimitThenTheSlopeAgainstTheMotion) {
  CHECK(speed_penalty_n({0.0009, 0.0, 0.0}, kLimit, kForceLimit, kSlope).isZero());
  // 350 N s/m x (8 - 1) mm/s.
  const Eigen::Vector3d penalty = speed_penalty_n({0.008, 0.0, 0.0}, kLimit, kForceLimit, kSlope);
  DOUBLES_EQUAL(-2.45, penalty.x(), 1e-12);
  DOUBLES_EQUAL(0.0, penalty.y(), 0.0);
  DOUBLES_EQUAL(0.0, penalty.z(), 0.0);
}

TEST(SpeedPenalty, ItOpposesTheVelocityInAnyDirection) {
  const Eigen::Vector3d velocity(0.003, -0.004, 0.0);  // 5 mm/s
  const Eigen::Vector3d penalty = speed_penalty_n(velocity, kLimit, kForceLimit, kSlope);
  DOUBLES_EQUAL(kSlope * (0.005 - 0.001), penalty.norm(), 1e-12);
  DOUBLES_EQUAL(-1.0, penalty.normalized().dot(velocity.normalized()), 1e-12);
}

TEST(SpeedPenalty, ARushingHandGetsTheForceLimitAndNoMore) {
  DOUBLES_EQUAL(kForceLimit, speed_penalty_n({0.0, 0.0, -1.0}, kLimit, kForceLimit, kSlope).norm(), 1e-12);
  DOUBLES_EQUAL(kForceLimit, speed_penalty_n({0.02, 0.0, 0.0}, kLimit, kForceLimit, kSlope).norm(), 1e-12);
}

TEST(SpeedPenalty, WhereTheSlopeCanReachTheForceLimitFromLaterOnTheOnsetMovesThere) {
  // A mill ten times faster: the line from 100 - 5 / 350 m/s reaches 5 N at the limit itself, so
  // any push under the force limit is held under the speed limit.
  const double limit = 0.1;
  const double onset = limit - kForceLimit / kSlope;
  CHECK(speed_penalty_n({onset - 1e-6, 0.0, 0.0}, limit, kForceLimit, kSlope).isZero());
  DOUBLES_EQUAL(kForceLimit, speed_penalty_n({limit, 0.0, 0.0}, limit, kForceLimit, kSlope).norm(), 1e-9);
  DOUBLES_EQUAL(kSlope * 0.004, speed_penalty_n({onset + 0.004, 0.0, 0.0}, limit, kForceLimit, kSlope).norm(), 1e-9);
}

TEST(SpeedPenalty, ATwoNewtonPushIsHeldUnderTheLimitAlongAnAxisAndAHorizontalDiagonal) {
  // Along (1, 1, 0) the cap's |dx| + |dy| bound lets the mill follow 1 / sqrt 2 of its speed.
  for (const double limit : {kLimit, kLimit / std::sqrt(2.0)}) {
    const double balance = 0.1 * limit + 2.0 / kSlope;  // where the penalty balances the push
    CHECK(balance < limit);
    DOUBLES_EQUAL(2.0, speed_penalty_n({balance, 0.0, 0.0}, limit, kForceLimit, kSlope).norm(), 1e-12);
  }
}

TEST(SpeedPenalty, NoCapOrAnInputThatIsNotANumberGivesNothing) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d fast(0.05, 0.0, 0.0);
  CHECK(speed_penalty_n(fast, inf, kForceLimit, kSlope).isZero());
  CHECK(speed_penalty_n({nan, 0.0, 0.0}, kLimit, kForceLimit, kSlope).isZero());
  CHECK(speed_penalty_n(fast, kLimit, nan, kSlope).isZero());
  CHECK(speed_penalty_n(fast, kLimit, kForceLimit, nan).isZero());
  CHECK(speed_penalty_n(fast, kLimit, kForceLimit, kSlope, nan).isZero());
  CHECK(speed_penalty_n(fast, 0.0, kForceLimit, kSlope).isZero());
  CHECK(speed_penalty_n(fast, kLimit, 0.0, kSlope).isZero());
  CHECK(speed_penalty_n(Eigen::Vector3d::Zero(), kLimit, kForceLimit, kSlope).isZero());
}

TEST(SpeedPenalty, TheMillFollowsLessAlongADiagonalThanAlongAnAxis) {
  DOUBLES_EQUAL(1.0, mill_speed_along({-3.0, 0.0, 0.0}, 1.0, 1.0), 1e-12);
  // |vx| + |vy| at most 1: along (1, 1) the speed is 1 / sqrt 2.
  DOUBLES_EQUAL(1.0 / std::sqrt(2.0), mill_speed_along({1.0, 1.0, 0.0}, 1.0, 1.0), 1e-12);
  // The per-axis bound alone: along (1, 1) each axis may move at 1, so sqrt 2.
  DOUBLES_EQUAL(std::sqrt(2.0), mill_speed_along({1.0, 1.0, 0.0}, 1.0, std::numeric_limits<double>::infinity()), 1e-12);
  CHECK(std::isinf(mill_speed_along(Eigen::Vector3d::Zero(), 1.0, 1.0)));
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(std::isinf(mill_speed_along({1.0, 2.0, 3.0}, inf, inf)));
}
