// Coulomb friction on the part (stencil/surface_friction.hpp): inside the cone the tool stays, outside
// it slides along the surface until the pull along it is the coefficient times the push into it.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/surface_friction.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::engine;

namespace {

// A contact on a face whose outward normal is +z, pushing the tool out with `force_n`.
ContactResult on_top_face(double force_n) {
  return {QueryStatus::Ok, 3, 0.05, 0, Eigen::Vector3d(0.0, 0.0, force_n), Eigen::Vector3d::Zero()};
}

const Eigen::Vector3d kTip(10.0, 5.0, 6.0);
constexpr double kCoupling = 5.0;  // N per world mm: 0.5 N per device mm at the rig's scale

}  // namespace

TEST_GROUP(SurfaceFriction){};

TEST(SurfaceFriction, WithNoFrictionOrNoContactTheGoalIsTheHand) {
  const Eigen::Vector3d desired = kTip + Eigen::Vector3d(0.3, 0.0, -0.2);
  CHECK(friction_goal(kTip, desired, on_top_face(1.0), kCoupling, 0.0).goal_mm == desired);
  ContactResult none = on_top_face(0.0);
  none.penetrating_points = 0;
  const FrictionGoal free = friction_goal(kTip, desired, none, kCoupling, 0.5);
  CHECK(free.goal_mm == desired);
  CHECK_FALSE(free.in_contact);
}

TEST(SurfaceFriction, InsideTheConeTheToolStaysWhereItIs) {
  // Push: 0.2 mm x 5 N/mm + 1 N of contact = 2 N; mu 0.5 holds 1 N along: 0.2 mm of stretch.
  const FrictionGoal goal = friction_goal(kTip, kTip + Eigen::Vector3d(0.19, 0.0, -0.2), on_top_face(1.0), kCoupling, 0.5);
  CHECK(goal.in_contact);
  CHECK(goal.sticking);
  CHECK(goal.goal_mm == kTip);
}

TEST(SurfaceFriction, OutsideTheConeTheToolSlidesUntilThePullIsMuTimesThePush) {
  const Eigen::Vector3d desired = kTip + Eigen::Vector3d(0.6, 0.8, -0.2);  // 1 mm along, 2 N of push
  const FrictionGoal goal = friction_goal(kTip, desired, on_top_face(1.0), kCoupling, 0.5);
  CHECK(goal.in_contact);
  CHECK_FALSE(goal.sticking);
  DOUBLES_EQUAL(kTip.z(), goal.goal_mm.z(), 1e-12);  // along the surface only
  const Eigen::Vector3d left = desired - goal.goal_mm;
  const double pull_n = kCoupling * std::hypot(left.x(), left.y());
  const double push_n = kCoupling * 0.2 + 1.0;
  DOUBLES_EQUAL(0.5, pull_n / push_n, 1e-12);
  // The way it slid is the way the hand pulled.
  DOUBLES_EQUAL(0.0, left.x() / left.norm() * 0.8 - left.y() / left.norm() * 0.6, 1e-9);
}

TEST(SurfaceFriction, AHandPullingAwayFromTheSurfaceIsNotHeld) {
  // The hand above the tool, though its point still penetrates (the tool keeps a standoff): free.
  const Eigen::Vector3d desired = kTip + Eigen::Vector3d(0.05, 0.0, 0.1);
  const FrictionGoal goal = friction_goal(kTip, desired, on_top_face(0.1), kCoupling, 0.5);
  CHECK_FALSE(goal.in_contact);
  CHECK_FALSE(goal.sticking);
  CHECK(goal.goal_mm == desired);
}

TEST(SurfaceFriction, NotANumberAnywhereGivesTheHandsPoint) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d desired = kTip + Eigen::Vector3d(0.1, 0.0, -0.2);
  CHECK_FALSE(friction_goal(kTip, desired, on_top_face(1.0), kCoupling, nan).in_contact);
  CHECK_FALSE(friction_goal(kTip, desired, on_top_face(nan), kCoupling, 0.5).in_contact);
  CHECK_FALSE(friction_goal(Eigen::Vector3d(nan, 0, 0), desired, on_top_face(1.0), kCoupling, 0.5).in_contact);
  CHECK_FALSE(friction_goal(kTip, desired, on_top_face(1.0), 0.0, 0.5).in_contact);
}
