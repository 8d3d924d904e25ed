// The simulation board's frames, cycle configuration and default stock (board/sim/sim_job): the
// configured rig's frames beside the simulated mill's truth, and the stock around a part. Running a
// job (run_fast, run_realtime) is end to end: the e2e cases sim_raster_corner, sim_plunge and the rest.
#include <Eigen/Core>

#include "board/sim/sim_job.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

TEST_GROUP(SimJob){};

TEST(SimJob, TheFramesAreTheConfiguredRigsFromItsHome) {
  SimRig rig;
  rig.home_world_mm = {40.0, 20.0, 22.0};
  const motion::MachineFrames f = frames(rig);
  DOUBLES_EQUAL(10.0, f.device_mm_per_world_mm, 0.0);
  DOUBLES_EQUAL(40.0, f.home_world_mm.x(), 0.0);
  DOUBLES_EQUAL(22.0, f.home_world_mm.z(), 0.0);
  DOUBLES_EQUAL(640.0, f.steps_per_mm, 0.0);
  CHECK_EQUAL(-1, f.machine_sign[2]);
}

TEST(SimJob, TheTrueFramesTakeTheMillsStepsAndSignsButTheConfiguredHome) {
  SimRig rig;
  rig.mill_truth.steps_per_mm = 600.0;
  rig.mill_truth.machine_sign = {-1, 1, -1};
  const motion::MachineFrames truth = true_frames(rig);
  DOUBLES_EQUAL(600.0, truth.steps_per_mm, 0.0);
  CHECK_EQUAL(1, truth.machine_sign[1]);
  DOUBLES_EQUAL(rig.home_world_mm[0], truth.home_world_mm.x(), 0.0);
  DOUBLES_EQUAL(640.0, frames(rig).steps_per_mm, 0.0);  // the controller still believes the configuration
}

TEST(SimJob, TheCyclesConfigurationIsTheConfiguredRigs) {
  SimRig rig;
  rig.facts.haptic_rate_hz = 500.0;
  const control::ControllerConfig config = controller_config(false, rig);
  DOUBLES_EQUAL(2e-3, config.period_s, 1e-15);
  DOUBLES_EQUAL(10.0, config.frames.device_mm_per_world_mm, 0.0);
}

TEST(SimJob, TheDefaultStockIsThePartGrownBy2MmInXAndYFromTheFloorTo1MmAboveIt) {
  const test::LoadedPart loaded(test::default_part(), 1);
  CHECK_TRUE(loaded.loaded);
  const stencil::sim::StockBox stock = default_stock(loaded.part);
  // The prism: circumradius 8 mm, height 6 mm, centred in the 50 x 25 workspace.
  DOUBLES_EQUAL(0.0, stock.low_mm.z(), 0.0);
  DOUBLES_EQUAL(7.0, stock.high_mm.z(), 1e-5);
  DOUBLES_EQUAL(25.0 - 8.0 - 2.0, stock.low_mm.x(), 1e-5);
  DOUBLES_EQUAL(25.0 + 8.0 + 2.0, stock.high_mm.x(), 1e-5);
  // Within the workspace whatever the margin.
  CHECK(stock.low_mm.y() >= 0.0);
  CHECK(stock.high_mm.y() <= 25.0);
}
