// The simulated device's own thread: step() every period on absolute CLOCK_MONOTONIC deadlines.
#include "sim/haptic_device/simulated_device_thread.hpp"

#include "hal/posix_clock/monotonic_clock.hpp"

namespace stencil::sim {

SimulatedDeviceThread::SimulatedDeviceThread(SimulatedHapticDevice& device, hal::MonotonicNs period_ns)
    : device_(device), thread_([this, period_ns] { run(period_ns); }) {}

SimulatedDeviceThread::~SimulatedDeviceThread() { stop(); }

void SimulatedDeviceThread::stop() {
  running_.store(false, std::memory_order_relaxed);
  if (thread_.joinable()) thread_.join();
}

void SimulatedDeviceThread::run(hal::MonotonicNs period_ns) {
  hal::MonotonicNs deadline_ns = hal::posix_clock::monotonic_now_ns();
  while (running_.load(std::memory_order_relaxed)) {
    device_.step(hal::posix_clock::monotonic_now_ns());
    cycles_.fetch_add(1, std::memory_order_relaxed);
    deadline_ns += period_ns;
    const hal::MonotonicNs now_ns = hal::posix_clock::monotonic_now_ns();
    if (deadline_ns < now_ns) deadline_ns = now_ns;  // overran (a loaded machine): no burst to catch up
    hal::posix_clock::sleep_until_monotonic_ns(deadline_ns);
  }
}

}  // namespace stencil::sim
