// The virtual tool's speed limit (motion/speed_limit.hpp) on the Sherline's numbers (1.4 mm/s an
// axis, 1000 steps/s for the three together, 640 steps/mm): which bound binds, that the direction
// is kept, and that a bad input leaves the tool where it is.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/motion/speed_limit.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::motion;

namespace {

const MachineSpeed kSherline{1.4, 1000.0, 640.0};

}  // namespace

TEST_GROUP(SpeedLimit){};

TEST(SpeedLimit, NoAxisFasterThanTheMillAndAllAxesTogetherWithinTheStepRate) {
  const MachineSpeed speed = kSherline;
  const Eigen::Vector3d along_x = limit_tool_move(speed, Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0), 0.001);
  DOUBLES_EQUAL(0.0014, along_x.x(), 1e-15);
  const Eigen::Vector3d diagonal = limit_tool_move(speed, Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 1, 1), 0.001);
  DOUBLES_EQUAL(1000.0 / 640.0 * 0.001, diagonal.cwiseAbs().sum(), 1e-15);  // the step rate binds
  DOUBLES_EQUAL(diagonal.x(), diagonal.z(), 1e-18);                          // direction kept
  const Eigen::Vector3d slow(0.0001, 0.0, -0.0002);
  CHECK(limit_tool_move(speed, Eigen::Vector3d::Zero(), slow, 0.001) == slow);
  CHECK(limit_tool_move(speed, Eigen::Vector3d::Ones(), Eigen::Vector3d(NAN, 0, 0), 0.001) == Eigen::Vector3d::Ones());
}

TEST(SpeedLimit, TheBoundGrowsWithTheTimeGivenAndHoldsFromAnyStartingPoint) {
  const Eigen::Vector3d from(10.0, -4.0, 3.0);
  // 0.1 s: 0.14 mm on one axis; going -y, the largest axis is bound, not the signed coordinate.
  const Eigen::Vector3d to = limit_tool_move(kSherline, from, from + Eigen::Vector3d(0.0, -5.0, 0.0), 0.1);
  DOUBLES_EQUAL(-4.14, to.y(), 1e-12);
  DOUBLES_EQUAL(10.0, to.x(), 0.0);
  DOUBLES_EQUAL(3.0, to.z(), 0.0);
}

TEST(SpeedLimit, NoTimeOrATimeThatIsNotANumberLeavesTheToolWhereItIs) {
  const Eigen::Vector3d from(1.0, 2.0, 3.0);
  const Eigen::Vector3d to(1.0001, 2.0, 3.0);  // short enough for any positive time
  CHECK(limit_tool_move(kSherline, from, to, 0.0) == from);
  CHECK(limit_tool_move(kSherline, from, to, -0.001) == from);
  CHECK(limit_tool_move(kSherline, from, to, std::numeric_limits<double>::quiet_NaN()) == from);
  CHECK(limit_tool_move(kSherline, from, Eigen::Vector3d(1.0, std::numeric_limits<double>::infinity(), 3.0), 0.001) ==
        from);
}
