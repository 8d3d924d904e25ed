// The one rule for how far a tip may move in a step (stencil/move_limit.hpp): per axis and over the
// axes together, whichever binds harder, the direction kept and the flag saying it was shortened.
#include <Eigen/Core>

#include "firmware/core/stencil/move_limit.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::engine;

TEST_GROUP(MoveLimit){};

TEST(MoveLimit, AMoveWithinBothBoundsIsTheTargetItselfUnshortened) {
  const Eigen::Vector3d from(1.0, 2.0, 3.0);
  const Eigen::Vector3d to(1.25, 1.75, 3.125);  // largest axis 0.25, total 0.625: both exactly at their bound
  bool shortened = true;
  CHECK(shorten_move(from, to, 0.25, 0.625, shortened) == to);
  CHECK_FALSE(shortened);
  CHECK(shorten_move(from, from, 0.0, 0.0, shortened) == from);  // no move fits any bound
  CHECK_FALSE(shortened);
}

TEST(MoveLimit, TheLargestAxisIsHeldToThePerAxisBoundInTheMovesDirection) {
  const Eigen::Vector3d from(1.0, 2.0, 3.0);
  bool shortened = false;
  const Eigen::Vector3d at = shorten_move(from, from + Eigen::Vector3d(-4.0, 2.0, 0.0), 1.0, 100.0, shortened);
  CHECK(shortened);
  CHECK(((at - from) - Eigen::Vector3d(-1.0, 0.5, 0.0)).norm() < 1e-15);
}

TEST(MoveLimit, TheAxesTogetherAreHeldToTheTotalBoundWhenItBindsHarder) {
  const Eigen::Vector3d from = Eigen::Vector3d::Zero();
  bool shortened = false;
  // Per axis 1.0 would allow (1, -1, 1), a total of 3; the total bound of 1.5 allows half of that.
  const Eigen::Vector3d at = shorten_move(from, Eigen::Vector3d(2.0, -2.0, 2.0), 1.0, 1.5, shortened);
  CHECK(shortened);
  DOUBLES_EQUAL(1.5, at.cwiseAbs().sum(), 1e-15);
  CHECK((at - Eigen::Vector3d(0.5, -0.5, 0.5)).norm() < 1e-15);
  // And the per-axis bound when it is the harder one: (0.2, -0.2, 0.2), total 0.6 < 1.5.
  CHECK((shorten_move(from, Eigen::Vector3d(2.0, -2.0, 2.0), 0.2, 1.5, shortened) - Eigen::Vector3d(0.2, -0.2, 0.2))
            .norm() < 1e-15);
}
