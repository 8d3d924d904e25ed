// stencil-rig's run loop (board sherline_suzuki) on the wall clock against the fakes: the real PIO
// backend over a memfd window with a simulated device writing it from a thread of its own at
// 1 kHz, and the real CY545 driver over a pseudo-terminal to the fake CY545 and its mill. The same
// code the rig runs, with the real-time runner (which runs without privileges where there are none).
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>

#include <unistd.h>

#include <pthread.h>
#include <sched.h>

#include "board/sim/sim_facts.hpp"
#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/runtime/realtime_thread.hpp"
#include "firmware/core/tables/table_loader.hpp"
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
  sim::SimulatedMill mill{board::sim::kMillConfig};
  sim::cy545::FakeCy545 fake{mill, board::sim::kMmc4sWiring, hal::posix_clock::monotonic_now_ns()};
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

  // The hand holds the handle where the tool is at home, then draws it 1 mm (world) towards -x.
  static sim::SimulatedPose drawn_back(std::uint32_t counter, hal::MonotonicNs) {
    const double moved = std::min(10.0, 0.005 * counter);  // device mm: 5 mm/s, for 2 s
    return sim::SimulatedPose{{500.0 - moved, 250.0, 250.0}, {0.0, 0.0}};
  }

  explicit FakeRig(const sim::PoseSource& pose = drawn_back) {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    fake_runner = std::make_unique<sim::cy545::FakeCy545Runner>(fake);
    char port_error[256] = {};
    CHECK_TRUE(port.open(fake.slave_path().c_str(), rig::kRig.serial_baud, port_error));
    hal::cy545::Cy545Config config = rig::kCy545;
    config.motion.homing_rate = 20000;  // the fake homes in a fraction of a second
    config.motion.homing_slow_rate = 5000;
    config.reply_timeout_ns = 1'000'000'000;  // the fake is a thread on a host that is not real-time (and CI's sanitizers)
    link = std::make_unique<hal::cy545::Cy545Link>(port, clock, config);
    window = hal::pio_shared_memory::SharedWindowMapping::create_memfd("rig-loop-tests", error);
    CHECK(window != nullptr);
    device_link = std::make_unique<sim::PioDeviceLink>(window->window());
    // The device trips after 200 ms of a frozen host heartbeat, not the card's 20: the host cycle here
    // is a thread on a host that is not real-time (as stale_periods and overrun_limit below).
    device = std::make_unique<sim::SimulatedHapticDevice>(*device_link, pose, 200'000'000);
    host = std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&window->window(), rig::kDeviceRange);
    device->step(hal::posix_clock::monotonic_now_ns());
    device_thread = std::thread([this] {
      // The device's own loop is hard real time on its card: SCHED_FIFO here where allowed, so
      // the host's noise does not make it look stale.
      sched_param param{};
      param.sched_priority = 70;
      static_cast<void>(pthread_setschedparam(pthread_self(), SCHED_FIFO, &param));
      auto next = std::chrono::steady_clock::now();
      while (device_running.load()) {
        next += std::chrono::milliseconds(1);
        std::this_thread::sleep_until(next);
        if (!device_frozen.load()) {
          device->step(hal::posix_clock::monotonic_now_ns());
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
    j.facts.start_held = false;  // the scripted hands move from the first millisecond (the held start: control_tests)
    j.part = &part;
    j.device = host.get();
    j.machine = link.get();
    j.machine_clock = &clock;
    j.stock = {{0.0, 0.0, 0.0}, {50.0, 25.0, 25.0}};
    j.duration_s = duration_s;
    // Not a real-time host: overruns are counted but do not end the run here (the overrun storm has
    // its own test in tests/control).
    j.facts.overrun_limit = 1'000'000;
    j.facts.stale_periods = 100;  // 0.1 s: a stalled thread here is not a disconnected device
    return j;
  }

  [[nodiscard]] bool spindle_on() {
    bool on = false;
    fake_runner->with_fake([&](sim::cy545::FakeCy545& f) { on = f.board().general_output(4); });
    return on;
  }
};

runtime::PeriodicRunner unprivileged_runner() {
  return app::realtime_runner({80, -1, false}, [](const std::string&) {});
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

TEST(RigLoop, ADeviceThatFreezesIsASafeStateWithTheMillStoppedAndNoForceUntilTheRunEnds) {
  FakeRig rig;
  std::thread freezer([&rig] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // homing, then some cutting
    rig.device_frozen.store(true);
  });
  const rig::RigResult result = rig::run_rig(rig.job(3.0), unprivileged_runner());
  freezer.join();
  CHECK(result.run_s > 2.5);  // the safe state did not end the run: its time did
  CHECK_TRUE(result.started);
  // The backend's heartbeat watchdog sees the frozen device first here (the cycle's own stale
  // watchdog is raised to 0.1 s for this host); on the rig, 5 periods without a sample come first.
  STRCMP_EQUAL("device_fault", control::safe_reason_name(result.first_fault));
  STRCMP_EQUAL("device_fault", control::safe_reason_name(result.safe_state));  // latched to the end
  CHECK_FALSE(rig.spindle_on());
  // The last thing the host wrote to the device: no force, enable off.
  rig.stop_device_thread();
  rig.device_frozen.store(false);
  rig.device->step(hal::posix_clock::monotonic_now_ns());
  const sim::DeviceOutput output = rig.device->output();
  CHECK_FALSE(output.force_applied);
  DOUBLES_EQUAL(0.0, std::hypot(output.force_n[0], output.force_n[1], output.force_n[2]), 0.0);
}

// A jerk of the handle (a sample 100 mm off for 3 ms) is a pose jump; the operator then holds the
// handle still where it was and types reset: refused while it has not been still for 0.5 s, then
// taken.
TEST(RigLoop, APoseJumpIsASafeStateThatAResetLeavesOnceTheHandleIsHeldStill) {
  std::atomic<std::uint32_t> jump_at{0xffffffffU};
  std::atomic<std::uint32_t> latest{0};
  FakeRig rig([&jump_at, &latest](std::uint32_t counter, hal::MonotonicNs) {
    latest.store(counter);
    const bool off = counter >= jump_at.load() && counter < jump_at.load() + 3;
    return sim::SimulatedPose{{off ? 400.0 : 500.0, 250.0, 250.0}, {0.0, 0.0}};
  });
  std::atomic<int> resets_to_send{0};
  std::atomic<bool> running{false};
  rig::RigJob job = rig.job(4.0);
  job.operator_command = [&resets_to_send, &running]() -> std::optional<control::CommandKind> {
    running.store(true);  // polled once the machine is homed and the cycle runs
    if (resets_to_send.load() > 0) {
      resets_to_send.fetch_sub(1);
      return control::CommandKind::Reset;
    }
    return std::nullopt;
  };
  std::thread operator_hand([&] {
    while (!running.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    jump_at.store(latest.load() + 50);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    resets_to_send.store(1);  // 150 ms after the jump: not yet still for 0.5 s
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    resets_to_send.store(1);  // still for over a second now
  });
  const rig::RigResult result = rig::run_rig(job, unprivileged_runner());
  operator_hand.join();
  STRCMP_EQUAL("pose_jump", control::safe_reason_name(result.first_fault));
  LONGS_EQUAL(1, result.resets_refused);
  LONGS_EQUAL(1, result.resets_accepted);
  STRCMP_EQUAL("stopped", control::safe_reason_name(result.safe_state));
  CHECK_FALSE(rig.spindle_on());  // stopped at the jump, and it stays stopped
}

// A job carried on from its journal (as after a kill): the run before is rebuilt from the record
// (its cycles, its machine commands, the touched set and the model of the stock it cut), the mill
// homes again before it moves, and the journal goes on in the same file with the second run's.
TEST(RigLoop, AJobCarriedOnFromItsJournalRebuildsWhatWasCutAndHomesAgain) {
  char name[] = "/tmp/rig_loop_journal_XXXXXX";
  const int fd = mkstemp(name);
  CHECK(fd >= 0);
  close(fd);
  const std::string path = name;
  rig::RigResult first;
  {
    FakeRig rig;
    journal::JournalWriter writer;
    journal::JournalStart start;
    start.tables_crc32 = rig.part.header.crc32;
    start.triangle_count = rig.part.header.triangle_count;
    start.program = "rig_loop_tests";
    CHECK_TRUE(writer.open(path, start));
    rig::RigJob job = rig.job(1.5);
    job.stock = {{0.0, 0.0, 0.0}, {50.0, 25.0, 25.5}};  // the 1 mm draw at home's height cuts its top
    job.journal = &writer;
    first = rig::run_rig(job, unprivileged_runner());
    CHECK_TRUE(first.started);
    CHECK_TRUE(writer.close());  // no End record: as if the run had been killed
  }
  CHECK(first.model_removed_mm3 > 0.0);
  journal::JobHistory before;
  std::string error;
  FakeRig rig;
  const motion::MachineFrames frames = rig::rig_frames({});
  CHECK_TEXT(journal::read_job_history(path, rig.part.header.crc32, rig.part.header.triangle_count, frames, {}, before, error), error.c_str());
  LONGS_EQUAL(1, before.homings);
  CHECK(before.machine_commands >= first.machine_updates && before.machine_commands > 0);
  CHECK_FALSE(before.endings[0].recorded);
  journal::JournalWriter writer;
  journal::JournalResume resume;
  resume.segment = 1;
  CHECK_TRUE(writer.open_to_resume(path, before.good_bytes, resume));
  rig::RigJob job = rig.job(1.0);
  job.stock = {{0.0, 0.0, 0.0}, {50.0, 25.0, 25.5}};
  job.journal = &writer;
  job.resume_from = path;
  job.resume_bytes = before.good_bytes;
  const rig::RigResult second = rig::run_rig(job, unprivileged_runner());
  CHECK_TRUE(writer.close());
  STRCMP_EQUAL("", second.error.c_str());
  LONGS_EQUAL(1, second.earlier.segments);
  LONGS_EQUAL(before.cycles, second.earlier.cycles);
  LONGS_EQUAL(second.earlier.touched_recorded, second.touched_rebuilt);
  // The model starts from what the first run cut (the second repeats the same draw).
  CHECK(second.model_removed_mm3 >= first.model_removed_mm3 - 1e-9);
  journal::JobHistory after;
  CHECK_TRUE(journal::read_job_history(path, rig.part.header.crc32, rig.part.header.triangle_count, frames, {}, after, error));
  LONGS_EQUAL(2, after.segments);
  LONGS_EQUAL(2, after.homings);  // homed again before anything moved
  CHECK(after.cycles > before.cycles);
  std::remove(path.c_str());
}

// Issue 18, item 4: the spindle came on unattended right after homing. Now the rig asks the operator
// first; an answer that never comes (input closed, Ctrl-C) leaves it off, drivers off, nothing cut.
TEST(RigLoop, TheSpindleStartsOnlyOnceTheOperatorConfirms) {
  FakeRig rig;
  rig::RigJob job = rig.job(1.0);
  bool asked_while_homed = false;
  job.confirm_spindle = [&] {
    asked_while_homed = rig.link->status().homed && !rig.spindle_on();
    return false;
  };
  const rig::RigResult result = rig::run_rig(job, unprivileged_runner());
  CHECK_TRUE(asked_while_homed);
  CHECK_FALSE(result.started);
  STRCMP_CONTAINS("not confirmed", result.error.c_str());
  CHECK_FALSE(rig.spindle_on());
  CHECK_FALSE(rig.fake_runner->with_fake([&](sim::cy545::FakeCy545&) { return rig.mill.drivers_enabled(); }));
}
