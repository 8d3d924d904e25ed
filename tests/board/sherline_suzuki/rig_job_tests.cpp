// The rig's frames and its cycle's configuration (board/sherline_suzuki/rig_job): world = device / 10
// from the work offset, a tool that sticks out further putting the tip lower at home, and the
// configuration's own overrun limit, stale periods and held start taken into the cycle. run_rig
// itself runs on threads and the wall clock: tests/e2e/rig_loop_tests.cpp.
#include <Eigen/Core>

#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/core/motion/machine_frames.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sherline_suzuki;

TEST_GROUP(RigJob){};

TEST(RigJob, TheFramesAreTheRigsScaleSignsAndStepsFromTheWorkOffset) {
  WorkOffset offset;
  offset.home_world_mm = Eigen::Vector3d(40.0, 20.0, 15.0);
  const motion::MachineFrames frames = rig_frames(offset);
  DOUBLES_EQUAL(10.0, frames.device_mm_per_world_mm, 0.0);
  DOUBLES_EQUAL(640.0, frames.steps_per_mm, 0.0);
  CHECK_EQUAL(-1, frames.machine_sign[0]);
  DOUBLES_EQUAL(40.0, frames.home_world_mm.x(), 0.0);
  DOUBLES_EQUAL(15.0, frames.home_world_mm.z(), 0.0);
  // The device's origin is the world's: device (100, 50, 30) is world (10, 5, 3).
  const Eigen::Vector3d world = motion::device_to_world(frames, Eigen::Vector3d(100.0, 50.0, 30.0));
  DOUBLES_EQUAL(10.0, world.x(), 1e-12);
  DOUBLES_EQUAL(3.0, world.z(), 1e-12);
}

TEST(RigJob, AToolStickingOutFurtherPutsTheTipLowerAtHome) {
  WorkOffset offset;
  offset.tool_stick_out_mm = 14.0;
  offset.reference_stick_out_mm = 10.0;
  const motion::MachineFrames frames = rig_frames(offset);
  DOUBLES_EQUAL(kHomeWorldMm[2] - 4.0, frames.home_world_mm.z(), 1e-12);
  DOUBLES_EQUAL(kHomeWorldMm[0], frames.home_world_mm.x(), 0.0);
}

TEST(RigJob, TheCyclesConfigurationTakesTheFactsOwnLimits) {
  RigJob job;
  job.facts.overrun_limit = 40;
  job.facts.stale_periods = 9;
  job.facts.start_held = false;
  job.facts.haptic_rate_hz = 500.0;
  const control::ControllerConfig config = rig_controller_config(job);
  CHECK_EQUAL(40, config.overrun_limit);
  CHECK_EQUAL(9, config.stale_periods);
  CHECK_FALSE(config.start_held);
  DOUBLES_EQUAL(2e-3, config.period_s, 1e-15);
  job.facts.start_held = true;
  CHECK_TRUE(rig_controller_config(job).start_held);
}
