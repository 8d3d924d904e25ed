// The maps between the device, the world and the machine (motion/machine_frames.hpp), on the
// Sherline's frames (its table axes count against the world) and on frames chosen so that every
// number is exact: the scale and origin, the steps' rounding and their 24-bit range.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/motion/machine_frames.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::motion;

namespace {

const Eigen::Vector3d kHome(25.0, 12.5, 20.0);  // above the prism

MachineFrames sherline_frames() { return {10.0, Eigen::Vector3d::Zero(), kHome, {-1, -1, 1}, 640.0}; }

// One step per millimetre from a home at the origin: the steps are the millimetres themselves.
MachineFrames unit_frames() { return {1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {1, 1, 1}, 1.0}; }

}  // namespace

TEST_GROUP(MachineFrames){};

TEST(MachineFrames, TheSherlinesTableAxesCountAgainstTheWorldAndStepsRoundTrip) {
  const MachineFrames frames = sherline_frames();
  MachineSteps steps{};
  CHECK(world_to_steps(frames, kHome + Eigen::Vector3d(1.0, 0.5, -2.0), steps));
  CHECK_EQUAL(-640, steps.axis[0]);  // the tool goes +x: the table goes -x
  CHECK_EQUAL(-320, steps.axis[1]);
  CHECK_EQUAL(-1280, steps.axis[2]);
  const Eigen::Vector3d back = steps_to_world(frames, steps);
  CHECK((back - (kHome + Eigen::Vector3d(1.0, 0.5, -2.0))).norm() < 1e-12);
  CHECK(world_to_steps(frames, kHome + Eigen::Vector3d(0.0007, -0.0008, 0.0), steps));  // nearest step
  CHECK_EQUAL(0, steps.axis[0]);
  CHECK_EQUAL(1, steps.axis[1]);
  CHECK_FALSE(world_to_steps(frames, Eigen::Vector3d(NAN, 0.0, 0.0), steps));
  CHECK_FALSE(world_to_steps(frames, Eigen::Vector3d(1e5, 0.0, 0.0), steps));  // beyond 24 bits of steps
  const Eigen::Vector3d world = device_to_world(frames, Eigen::Vector3d(250.0, 125.0, 200.0));
  CHECK((world - Eigen::Vector3d(25.0, 12.5, 20.0)).norm() < 1e-12);
  CHECK((world_to_device(frames, world) - Eigen::Vector3d(250.0, 125.0, 200.0)).norm() < 1e-12);
}

TEST(MachineFrames, TheDevicesOriginMapsToTheWorldsOriginAndItsScaleDividesItsMillimetres) {
  const MachineFrames frames{10.0, Eigen::Vector3d(100.0, -50.0, 30.0), kHome, {-1, -1, 1}, 640.0};
  CHECK(device_to_world(frames, Eigen::Vector3d(100.0, -50.0, 30.0)) == Eigen::Vector3d::Zero());
  CHECK(device_to_world(frames, Eigen::Vector3d(110.0, -70.0, 35.0)) == Eigen::Vector3d(1.0, -2.0, 0.5));
  CHECK(world_to_device(frames, Eigen::Vector3d(1.0, -2.0, 0.5)) == Eigen::Vector3d(110.0, -70.0, 35.0));
}

TEST(MachineFrames, AMachineReadoutIsTheSignedDistanceFromHomeUnrounded) {
  const MachineFrames frames = sherline_frames();
  const Eigen::Vector3d machine = world_to_machine_mm(frames, kHome + Eigen::Vector3d(1.0001, -0.25, -3.0));
  DOUBLES_EQUAL(-1.0001, machine.x(), 1e-12);  // not the nearest step (1/640 mm)
  DOUBLES_EQUAL(0.25, machine.y(), 1e-12);
  DOUBLES_EQUAL(-3.0, machine.z(), 1e-12);
  CHECK(world_to_machine_mm(frames, kHome) == Eigen::Vector3d::Zero());
}

TEST(MachineFrames, StepsUpToTwentyFourSignedBitsAreTakenAndOneMoreIsRefused) {
  const MachineFrames frames = unit_frames();
  const auto most = static_cast<double>(kMaxMachineSteps);
  MachineSteps steps{};
  CHECK(world_to_steps(frames, Eigen::Vector3d(most, -most, 0.0), steps));
  CHECK_EQUAL(kMaxMachineSteps, steps.axis[0]);
  CHECK_EQUAL(-kMaxMachineSteps, steps.axis[1]);
  CHECK_FALSE(world_to_steps(frames, Eigen::Vector3d(0.0, 0.0, most + 1.0), steps));
  CHECK_FALSE(world_to_steps(frames, Eigen::Vector3d(0.0, -most - 1.0, 0.0), steps));
  CHECK_FALSE(world_to_steps(frames, Eigen::Vector3d(0.0, std::numeric_limits<double>::infinity(), 0.0), steps));
}

TEST(MachineFrames, AHalfStepRoundsAwayFromHomeOnEitherSide) {
  const MachineFrames frames = unit_frames();
  MachineSteps steps{};
  CHECK(world_to_steps(frames, Eigen::Vector3d(2.5, -2.5, 0.49), steps));
  CHECK_EQUAL(3, steps.axis[0]);
  CHECK_EQUAL(-3, steps.axis[1]);
  CHECK_EQUAL(0, steps.axis[2]);
}
