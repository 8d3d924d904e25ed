// The simulated device in a process of its own (board/sim/device_process), in lockstep with the
// cycle: each step hands the child the cycle's time and the script's, and returns once the child's
// hand has moved and its sample is in the PIO window the host reads; stop() ends and reaps the child.
// What the child does once the controller's process is gone (the watchdog zeroing the force): e2e
// sim_kill_mid_cut_then_resume.
#include <cstdio>
#include <string>

#include <Eigen/Core>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/device_process.hpp"
#include "board/sim/simulated_device_wiring.hpp"
#include "sim/operator/operator_script.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

// A script from (200, 100, 100) to (300, 100, 100) device mm over 10 s.
stencil::sim::OperatorScript straight_script() {
  stencil::sim::OperatorScript script;
  script.t_s = {0.0, 10.0};
  script.device_mm = {Eigen::Vector3d(200.0, 100.0, 100.0), Eigen::Vector3d(300.0, 100.0, 100.0)};
  script.angles_rad = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  return script;
}

}  // namespace

TEST_GROUP(DeviceProcess){};

TEST(DeviceProcess, InLockstepEachStepsSampleReachesTheHost) {
  stencil::sim::OperatorHand hand;
  hand.handle_mm = Eigen::Vector3d(200.0, 100.0, 100.0);
  std::string error;
  SimulatedDeviceWiring wiring(HapticTransport::Pio, board::sherline_suzuki::kDeviceRange, hand, error);
  CHECK_TEXT(wiring.ready(), error.c_str());
  const stencil::sim::OperatorScript script = straight_script();
  DeviceProcess process;
  CHECK_FALSE(process.running());
  CHECK_TRUE(process.start(*wiring.simulated(), hand, script, 10.0, true, stderr));
  CHECK_TRUE(process.running());

  hal::HapticSample sample{};
  bool fresh = false;
  hal::MonotonicNs now = 0;
  for (int i = 0; i < 20 && !fresh; ++i) {
    now += kMs;
    CHECK_TRUE(process.step(now, 0.0));
    fresh = wiring.host().read_sample(now, sample).status == hal::ReadStatus::Fresh;
  }
  CHECK_TRUE(fresh);
  DOUBLES_EQUAL(200.0, sample.position_mm[0], 0.01);
  // The script at 5 s is at x 250: the child's hand goes 0.3 of the way there in one step.
  now += kMs;
  CHECK_TRUE(process.step(now, 5.0));
  CHECK(wiring.host().read_sample(now, sample).status == hal::ReadStatus::Fresh);
  DOUBLES_EQUAL(215.0, sample.position_mm[0], 0.01);
  // This process's hand never moved: the child's is its own.
  DOUBLES_EQUAL(200.0, hand.handle_mm.x(), 0.0);
  CHECK_TRUE(process.force_off());

  process.stop();
  CHECK_FALSE(process.running());
}
