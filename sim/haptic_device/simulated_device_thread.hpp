// SimulatedDeviceThread: runs a SimulatedHapticDevice's step() on its own thread at a fixed period
// (1 kHz by default) on CLOCK_MONOTONIC (hal::posix_clock::monotonic_now_ns() is the time base it
// passes to step()), as the device's controller would. Not real-time code.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

#include "hal/clock.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"

namespace stencil::sim {

class SimulatedDeviceThread {
 public:
  // Starts stepping at once. `device` must outlive this object.
  explicit SimulatedDeviceThread(SimulatedHapticDevice& device, hal::MonotonicNs period_ns = 1'000'000);
  SimulatedDeviceThread(const SimulatedDeviceThread&) = delete;
  SimulatedDeviceThread& operator=(const SimulatedDeviceThread&) = delete;
  ~SimulatedDeviceThread();  // stops and joins

  void stop();
  [[nodiscard]] std::uint64_t cycles() const { return cycles_.load(std::memory_order_relaxed); }

 private:
  void run(hal::MonotonicNs period_ns);

  SimulatedHapticDevice& device_;
  std::atomic<bool> running_{true};
  std::atomic<std::uint64_t> cycles_{0};
  std::thread thread_;
};

}  // namespace stencil::sim
