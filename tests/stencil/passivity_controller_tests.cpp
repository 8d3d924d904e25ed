// The passivity observer and controller (stencil/passivity_controller.hpp): the work the held force
// did, added up; damping only while that balance is positive, sized to take it back in a period.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/passivity_controller.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using stencil::engine::PassivityController;

TEST_GROUP(PassivityController){};

TEST(PassivityController, TheBalanceIsTheWorkTheHeldForceDidOnTheHandle) {
  PassivityController pc;
  DOUBLES_EQUAL(-0.002, pc.observe({2.0, 0.0, 0.0}, {-1e-3, 0.0, 0.0}), 1e-15);  // pushed back against: absorbed
  DOUBLES_EQUAL(-0.002 + 0.003, pc.observe({0.0, 3.0, 0.0}, {0.0, 1e-3, 5e-3}), 1e-15);
  DOUBLES_EQUAL(0.001, pc.energy_j(), 1e-15);
}

TEST(PassivityController, NoDampingWhileTheWallHasTakenAtLeastWhatItGave) {
  PassivityController pc;
  static_cast<void>(pc.observe({1.0, 0.0, 0.0}, {-2e-3, 0.0, 0.0}));
  static_cast<void>(pc.observe({1.0, 0.0, 0.0}, {1e-3, 0.0, 0.0}));
  CHECK(pc.energy_j() < 0.0);
  CHECK(pc.correction({0.5, 0.0, 0.0}, 1e-3, 5.0).isZero());
}

TEST(PassivityController, APositiveBalanceIsTakenBackOverTheNextPeriodAgainstTheMotion) {
  PassivityController pc;
  static_cast<void>(pc.observe({1.0, 0.0, 0.0}, {1e-5, 0.0, 0.0}));  // 10 uJ put out
  const Eigen::Vector3d velocity(0.0, 0.02, 0.0);
  const Eigen::Vector3d force = pc.correction(velocity, 1e-3, 5.0);
  CHECK(force.dot(velocity) < 0.0);
  // Held over the next period at that velocity, the correction does -10 uJ of work.
  DOUBLES_EQUAL(-1e-5, force.dot(velocity * 1e-3), 1e-15);
}

TEST(PassivityController, TheCorrectionIsBoundedByItsDampingAndTheForceLimitAndNoneForAStillHandle) {
  PassivityController pc;
  static_cast<void>(pc.observe({5.0, 0.0, 0.0}, {1e-3, 0.0, 0.0}));  // 5 mJ: 50,000 N s/m at 0.01 m/s
  DOUBLES_EQUAL(PassivityController::kMaxDampingNSPerM * 0.01, pc.correction({0.01, 0.0, 0.0}, 1e-3, 5.0).norm(), 1e-12);
  DOUBLES_EQUAL(5.0, pc.correction({0.1, 0.0, 0.0}, 1e-3, 5.0).norm(), 1e-12);  // 10 N, limited to 5
  CHECK(pc.correction({PassivityController::kStillSpeedMPerS / 2.0, 0.0, 0.0}, 1e-3, 5.0).isZero());
}

TEST(PassivityController, NotANumberIsNeverAddedAndGivesNoCorrection) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PassivityController pc;
  static_cast<void>(pc.observe({1.0, 0.0, 0.0}, {1e-5, 0.0, 0.0}));
  static_cast<void>(pc.observe({nan, 0.0, 0.0}, {1e-3, 0.0, 0.0}));
  DOUBLES_EQUAL(1e-5, pc.energy_j(), 1e-18);
  CHECK(pc.correction({nan, 0.0, 0.0}, 1e-3, 5.0).isZero());
  CHECK(pc.correction({0.1, 0.0, 0.0}, 0.0, 5.0).isZero());
}

TEST(PassivityController, ARestartForgetsTheBalance) {
  PassivityController pc;
  static_cast<void>(pc.observe({1.0, 0.0, 0.0}, {1e-3, 0.0, 0.0}));
  pc.restart();
  DOUBLES_EQUAL(0.0, pc.energy_j(), 0.0);
  CHECK(pc.correction({0.1, 0.0, 0.0}, 1e-3, 5.0).isZero());
}
