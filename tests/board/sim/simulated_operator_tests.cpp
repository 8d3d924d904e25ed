// The simulated operator (board/sim/simulated_operator): the hand starting where the script starts,
// following the script a fraction of the way each device millisecond, holding still where the script
// had got to once the job's time is up, and the device process refused where it cannot run. The
// device's own process (--device-process): e2e sim_kill_mid_cut_then_resume.
#include <cstdio>
#include <string>

#include <Eigen/Core>

#include "board/sim/simulated_operator.hpp"
#include "board/sim/sim_job.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

// A script from (200, 100, 100) to (300, 100, 100) device mm over 10 s.
SimJob straight_job() {
  SimJob job;
  job.script.t_s = {0.0, 10.0};
  job.script.device_mm = {Eigen::Vector3d(200.0, 100.0, 100.0), Eigen::Vector3d(300.0, 100.0, 100.0)};
  job.script.angles_rad = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  return job;
}

runtime::CycleTime at(double t_s) { return {static_cast<hal::MonotonicNs>(t_s * 1e9), t_s}; }

// The device's sample after a cycle at `t_s`.
double x_after(SimulatedOperator& simulated, double t_s) {
  CHECK_TRUE(simulated.before_cycle(at(t_s)));
  hal::HapticSample sample{};
  CHECK(simulated.device().read_sample(at(t_s).now_ns, sample).status == hal::ReadStatus::Fresh);
  return sample.position_mm[0];
}

}  // namespace

TEST_GROUP(SimulatedOperator){};

TEST(SimulatedOperator, TheHandStartsWhereTheScriptStartsAndFollowsIt) {
  const SimJob job = straight_job();
  SimulatedOperator simulated(job, true);
  STRCMP_EQUAL("", simulated.start().c_str());
  DOUBLES_EQUAL(200.0, x_after(simulated, 0.0), 1e-9);
  // At 5 s the script is at x 250: the hand goes 0.3 of the way there (no force pushes back).
  DOUBLES_EQUAL(215.0, x_after(simulated, 5.0), 1e-9);
  DOUBLES_EQUAL(225.5, x_after(simulated, 5.0), 1e-9);
}

TEST(SimulatedOperator, AfterTheJobsTimeTheHandHoldsWhereTheScriptHadGot) {
  SimJob job = straight_job();
  job.duration_s = 2.0;  // the script is at x 220 then
  SimulatedOperator simulated(job, true);
  STRCMP_EQUAL("", simulated.start().c_str());
  double x = 0.0;
  for (int i = 0; i < 100; ++i) {
    x = x_after(simulated, 2.0 + 0.001 * i + (i > 50 ? 30.0 : 0.0));
  }
  DOUBLES_EQUAL(220.0, x, 1e-6);
}

TEST(SimulatedOperator, TheDeviceProcessRunsOnlyOverPioWithoutAFault) {
  SimJob job = straight_job();
  job.device_process_log = stderr;  // asked for; never started here
  SimulatedOperator direct(job, true);
  STRCMP_EQUAL("the device runs in its own process only over the PIO window, and with no fault injected",
               direct.start().c_str());
  job.transport = HapticTransport::Pio;
  job.fault = {FaultKind::PoseNan, 1.0};
  SimulatedOperator faulted(job, true);
  STRCMP_CONTAINS("only over the PIO window", faulted.start().c_str());
}

TEST(SimulatedOperator, TheForceOffIsTheDevicesInProcess) {
  const SimJob job = straight_job();
  SimulatedOperator simulated(job, true);
  STRCMP_EQUAL("", simulated.start().c_str());
  CHECK_TRUE(simulated.force_off());
  static_cast<void>(simulated.device().write_command({{1.0, 0.0, 0.0}, {0.0, 0.0}, 1, true}));
  CHECK_FALSE(simulated.force_off());
}

// Issue 29: a dynamic hand pulls the handle as a mass on a spring towards the script. With no force
// rendered, the medium hand (0.3 kg + the device's 0.2 kg on 300 N/m, 5 N s/m) starting at rest
// while the script runs at 10 mm/s lags behind it and catches up: it neither jumps to the script
// nor keeps today's placed hand's fixed fraction.
TEST(SimulatedOperator, ADynamicHandLagsTheScriptAsAMassOnASpringAndCatchesUp) {
  SimJob job = straight_job();
  job.hand = stencil::sim::kMediumHand;
  SimulatedOperator simulated(job, true);
  STRCMP_EQUAL("", simulated.start().c_str());
  DOUBLES_EQUAL(200.0, x_after(simulated, 0.0), 1e-9);
  double x = 200.0;
  for (int ms = 1; ms <= 10; ++ms) {
    x = x_after(simulated, 0.001 * ms);
  }
  // 10 ms in the script is at 200.1: the handle has barely started (it accelerates from rest).
  CHECK(x > 200.0 && x < 200.05);
  for (int ms = 11; ms <= 3000; ++ms) {
    x = x_after(simulated, 0.001 * ms);
  }
  // After 3 s (about 11 of its periods of 0.26 s, damped) it follows the script at 230 closely,
  // behind it by the Coulomb friction's 0.05 N over 300 N/m and the damping's lag at most.
  DOUBLES_EQUAL(230.0, x, 0.3);
  CHECK(x < 230.0);
}

TEST(SimulatedOperator, TheDeviceProcessMovesOnlyThePlacedHand) {
  SimJob job = straight_job();
  job.transport = HapticTransport::Pio;
  job.hand = stencil::sim::kStiffHand;
  job.device_process_log = stderr;  // asked for; never started here
  SimulatedOperator simulated(job, true);
  STRCMP_EQUAL("the device's own process moves the placed hand only, not a dynamic one", simulated.start().c_str());
}
