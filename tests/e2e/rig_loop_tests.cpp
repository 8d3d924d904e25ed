// stencil-rig's run loop (board sherline_suzuki) on the wall clock against the fakes: the real PIO
// backend over a memfd window with a simulated device writing it from a thread of its own at
// 1 kHz, and the real CY545 driver over a pseudo-terminal to the fake CY545 and its mill. The same
// code the rig runs, with the real-time runner (which runs without privileges where there are none).
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/app/realtime_thread.hpp"
#include "firmware/tables/table_loader.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_runner.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "sim/mill/simulated_mill.hpp"
#include "tests/support/sample_tables.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace rig = stencil::board::sherline_suzuki;

namespace {

// The rig, its far ends faked: everything a RigJob needs.
struct FakeRig {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  sim::SimulatedMill mill{sim::sherline_mill_config()};
  sim::cy545::FakeCy545 fake{mill, sim::cy545::FakeCy545Runner::monotonic_now_ns()};
  std::unique_ptr<sim::cy545::FakeCy545Runner> fake_runner;
  hal::cy545::SerialPort port;
  hal::posix_clock::MonotonicClock clock;
  std::unique_ptr<hal::cy545::Cy545Link> link;
  std::string error;
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> window;
  std::unique_ptr<sim::PioDeviceLink> device_link;
  std::unique_ptr<sim::SimulatedHapticDevice> device;
  std::unique_ptr<hal::pio_shared_memory::PioHapticDevice> host;
  std::atomic<bool> device_running{true};
  std::atomic<bool> device_frozen{false};
  std::thread device_thread;

  FakeRig() {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    fake_runner = std::make_unique<sim::cy545::FakeCy545Runner>(fake);
    char port_error[256] = {};
    CHECK_TRUE(port.open(fake.slave_path().c_str(), port_error));
    hal::cy545::Cy545Config config;
    config.homing_rate = 20000;  // the fake homes in a fraction of a second
    link = std::make_unique<hal::cy545::Cy545Link>(port, clock, config);
    window = hal::pio_shared_memory::SharedWindowMapping::create_memfd("rig-loop-tests", error);
    CHECK(window != nullptr);
    device_link = std::make_unique<sim::PioDeviceLink>(window->window());
    // The hand holds the handle where the tool is at home, then draws it 1 mm (world) towards -x.
    device = std::make_unique<sim::SimulatedHapticDevice>(*device_link, [](std::uint32_t counter, hal::MonotonicNs) {
      const double moved = std::min(10.0, 0.005 * counter);  // device mm: 5 mm/s, for 2 s
      return sim::SimulatedPose{{500.0 - moved, 250.0, 250.0}, {0.0, 0.0}};
    });
    host = std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&window->window(), hal::kCornerOriginHapticRange);
    device->step(sim::cy545::FakeCy545Runner::monotonic_now_ns());
    device_thread = std::thread([this] {
      auto next = std::chrono::steady_clock::now();
      while (device_running.load()) {
        next += std::chrono::milliseconds(1);
        std::this_thread::sleep_until(next);
        if (!device_frozen.load()) {
          device->step(sim::cy545::FakeCy545Runner::monotonic_now_ns());
        }
      }
    });
  }

  ~FakeRig() { stop_device_thread(); }

  void stop_device_thread() {
    device_running.store(false);
    if (device_thread.joinable()) {
      device_thread.join();
    }
  }

  [[nodiscard]] double mill_x_mm() {
    double x = 0.0;
    fake_runner->with_fake([&](sim::cy545::FakeCy545&) { x = mill.axis_position_mm(sim::Axis::x); });
    return x;
  }

  rig::RigJob job(double duration_s) {
    rig::RigJob j;
    j.part = &part;
    j.device = host.get();
    j.machine = link.get();
    j.machine_clock = &clock;
    j.stock = {{0.0, 0.0, 0.0}, {50.0, 25.0, 25.0}};
    j.duration_s = duration_s;
    // Not a real-time host: overruns are counted but do not end the run here (the overrun storm has
    // its own test in tests/control).
    j.overrun_limit = 1'000'000;
    return j;
  }

  [[nodiscard]] bool spindle_on() {
    bool on = false;
    fake_runner->with_fake([&](sim::cy545::FakeCy545& f) { on = f.board().general_output(4); });
    return on;
  }
};

rig::PeriodicRunner unprivileged_runner() {
  return [](hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
            const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>& cycle, std::string& refused) {
    const app::RealtimeSetup setup = app::run_periodic({80, -1, false}, period_ns, stop, cycle, [](const std::string&) {});
    refused = setup.refused;
    return setup.refused.empty();
  };
}

}  // namespace

TEST_GROUP(RigLoop){};

TEST(RigLoop, HomesFollowsTheDeviceAndStopsTheMillWhenItsTimeIsUp) {
  FakeRig rig;
  const rig::RigResult result = rig::run_rig(rig.job(2.0), unprivileged_runner());
  CHECK_TRUE(result.started);
  STRCMP_EQUAL("", result.error.c_str());
  STRCMP_EQUAL("stopped", control::safe_reason_name(result.safe_state));  // the run's own stop, when the time was up
  CHECK(result.cycles >= 1500 && result.cycles <= 2600);
  CHECK(result.machine_updates > 10);
  // The tool followed the hand: 1 mm (world) towards -x from home, so the mill's x moved.
  const double home_x_mm = 0.0;  // the machine's own coordinate at its switch
  CHECK(std::abs(rig.mill_x_mm() - home_x_mm) > 0.2);
  CHECK_FALSE(rig.spindle_on());  // stopped on the way out
}

TEST(RigLoop, ADeviceThatFreezesEndsTheRunInTheSafeStateWithTheMillStopped) {
  FakeRig rig;
  std::thread freezer([&rig] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // homing, then half a second of cutting
    rig.device_frozen.store(true);
  });
  const rig::RigResult result = rig::run_rig(rig.job(10.0), unprivileged_runner());
  freezer.join();
  CHECK_TRUE(result.started);
  CHECK(result.safe_state == control::SafeReason::DeviceStale);
  CHECK(result.run_s < 5.0);  // well before the duration
  CHECK_FALSE(rig.spindle_on());
  // The last thing the host wrote to the device: no force, enable off.
  rig.stop_device_thread();
  rig.device_frozen.store(false);
  rig.device->step(sim::cy545::FakeCy545Runner::monotonic_now_ns());
  const sim::DeviceOutput output = rig.device->output();
  CHECK_FALSE(output.force_applied);
  DOUBLES_EQUAL(0.0, std::hypot(output.force_n[0], output.force_n[1], output.force_n[2]), 0.0);
}
