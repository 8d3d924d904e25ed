// SimulatedDeviceThread: steps the simulated device on its own thread, once a period, until stopped;
// stop() (and the destructor) joins it, after which the device is not stepped again.
#include <chrono>
#include <cstdint>
#include <thread>

#include "sim/haptic_device/pio_device_link.hpp"
#include "sim/haptic_device/simulated_device_thread.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"
#include "tests/sim/haptic_device/counter_pose.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

TEST_GROUP(SimulatedDeviceThread) {
  test::WindowPair windows = test::make_device_window();
  sim::PioDeviceLink link{windows.device->window()};
  sim::SimulatedHapticDevice device{link, test::counter_pose};
};

TEST(SimulatedDeviceThread, StepsTheDeviceOncePerPeriodUntilStopped) {
  const auto start = std::chrono::steady_clock::now();
  sim::SimulatedDeviceThread thread(device, 2'000'000);
  std::this_thread::sleep_for(std::chrono::milliseconds(40));
  thread.stop();
  const auto elapsed_ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start).count();
  const std::uint64_t cycles = thread.cycles();
  // One step a period of the time it ran: a loaded machine may run fewer, never more.
  CHECK_TRUE(cycles >= 3);
  CHECK_TRUE(cycles <= static_cast<std::uint64_t>(elapsed_ms) / 2 + 1);
  LONGS_EQUAL(cycles, device.output().samples_written);  // one pose per step
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  LONGS_EQUAL(cycles, thread.cycles());  // stopped means stopped
  LONGS_EQUAL(cycles, device.output().samples_written);
}

TEST(SimulatedDeviceThread, TheDestructorStopsTheThread) {
  std::uint64_t cycles = 0;
  {
    sim::SimulatedDeviceThread thread(device);
    while (thread.cycles() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  cycles = device.output().samples_written;
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  LONGS_EQUAL(cycles, device.output().samples_written);
  CHECK_TRUE(cycles >= 2);
}
