// The job's one injected fault put in where it happens (board/sim/fault_injector): nothing before its
// time, once at the first cycle at or after it (never again), the cable pulled at the fake CY545's
// pty, an overrun storm making every cycle 1.5 periods late from then on; no fault, no injection.
// What each fault then does to a job: the e2e cases sim_fault_* (one per kind).
#include <memory>
#include <string>

#include "board/sim/fault_injector.hpp"
#include "board/sim/sim_facts.hpp"
#include "board/sim/sim_job.hpp"
#include "board/sim/simulated_device_wiring.hpp"
#include "firmware/core/control/controller.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/mill/simulated_mill.hpp"
#include "sim/operator/operator_script.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

constexpr hal::MonotonicNs kPeriod = 1'000'000;

// The parts an injector reaches: the device in process, the fake CY545 on its pty, a controller.
struct Rig {
  test::LoadedPart loaded{test::default_part(), 1};
  stencil::sim::OperatorHand hand;
  std::string error;
  SimulatedDeviceWiring device{HapticTransport::Direct, rig::kDeviceRange, hand, error};
  stencil::sim::SimulatedMill mill{kMillConfig};
  stencil::sim::cy545::FakeCy545 fake{mill, kMmc4sWiring, 0};
  std::unique_ptr<control::CycleRingStorage> rings = std::make_unique<control::CycleRingStorage>();
  std::unique_ptr<control::Controller> controller =
      std::make_unique<control::Controller>(loaded.part, device.host(), rings->rings(), controller_config(false));
};

runtime::CycleTime at(double t_s) { return {static_cast<hal::MonotonicNs>(t_s * 1e9), t_s}; }

}  // namespace

TEST_GROUP(FaultInjector){};

TEST(FaultInjector, PullsTheCableAtItsTimeAndOnlyThen) {
  Rig r;
  FaultInjector injector({FaultKind::SerialClosed, 2.0}, r.device, r.fake, *r.controller, kPeriod);
  CHECK_TRUE(injector.before_cycle(at(1.999)));
  CHECK(injector.injected() == FaultKind::None);
  DOUBLES_EQUAL(-1.0, injector.injected_s(), 0.0);
  CHECK_TRUE(r.fake.pty_open());
  CHECK_TRUE(injector.before_cycle(at(2.0005)));
  CHECK(injector.injected() == FaultKind::SerialClosed);
  DOUBLES_EQUAL(2.0005, injector.injected_s(), 0.0);
  CHECK_FALSE(r.fake.pty_open());
  CHECK_TRUE(injector.before_cycle(at(3.0)));
  DOUBLES_EQUAL(2.0005, injector.injected_s(), 0.0);  // once
  CHECK_EQUAL(0, injector.lateness_ns());
}

TEST(FaultInjector, AnOverrunStormMakesEveryCycleLateFromItsTime) {
  Rig r;
  FaultInjector injector({FaultKind::OverrunStorm, 0.5}, r.device, r.fake, *r.controller, kPeriod);
  CHECK_TRUE(injector.before_cycle(at(0.1)));
  CHECK_EQUAL(0, injector.lateness_ns());
  CHECK_TRUE(injector.before_cycle(at(0.5)));
  CHECK_EQUAL(1'500'000, injector.lateness_ns());
  CHECK_TRUE(injector.before_cycle(at(0.6)));
  CHECK_EQUAL(1'500'000, injector.lateness_ns());
  CHECK_TRUE(r.fake.pty_open());  // nothing else touched
}

TEST(FaultInjector, ADeviceFaultIsTheDevicesAndLeavesTheLineAlone) {
  Rig r;
  FaultInjector injector({FaultKind::DeviceFrozen, 0.0}, r.device, r.fake, *r.controller, kPeriod);
  CHECK_TRUE(injector.before_cycle(at(0.0)));
  CHECK(injector.injected() == FaultKind::DeviceFrozen);
  CHECK_TRUE(r.fake.pty_open());
  CHECK_EQUAL(0, injector.lateness_ns());
}

TEST(FaultInjector, NoFaultIsNeverInjected) {
  Rig r;
  FaultInjector injector({FaultKind::None, 0.0}, r.device, r.fake, *r.controller, kPeriod);
  CHECK_TRUE(injector.before_cycle(at(100.0)));
  CHECK(injector.injected() == FaultKind::None);
  DOUBLES_EQUAL(-1.0, injector.injected_s(), 0.0);
  CHECK_TRUE(r.fake.pty_open());
}
