// The simulated device's own thread: step() every period on absolute CLOCK_MONOTONIC deadlines.
#include "sim/haptic_device/simulated_device_thread.hpp"

#include <cerrno>
#include <ctime>

namespace stencil::sim {

hal::MonotonicNs monotonic_now_ns() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<hal::MonotonicNs>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

SimulatedDeviceThread::SimulatedDeviceThread(SimulatedHapticDevice& device, hal::MonotonicNs period_ns)
    : device_(device), thread_([this, period_ns] { run(period_ns); }) {}

SimulatedDeviceThread::~SimulatedDeviceThread() { stop(); }

void SimulatedDeviceThread::stop() {
  running_.store(false, std::memory_order_relaxed);
  if (thread_.joinable()) thread_.join();
}

void SimulatedDeviceThread::run(hal::MonotonicNs period_ns) {
  hal::MonotonicNs deadline_ns = monotonic_now_ns();
  while (running_.load(std::memory_order_relaxed)) {
    device_.step(monotonic_now_ns());
    cycles_.fetch_add(1, std::memory_order_relaxed);
    deadline_ns += period_ns;
    const hal::MonotonicNs now_ns = monotonic_now_ns();
    if (deadline_ns < now_ns) deadline_ns = now_ns;  // overran (a loaded machine): no burst to catch up
    timespec deadline{};
    deadline.tv_sec = static_cast<time_t>(deadline_ns / 1'000'000'000);
    deadline.tv_nsec = static_cast<long>(deadline_ns % 1'000'000'000);
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
  }
}

}  // namespace stencil::sim
