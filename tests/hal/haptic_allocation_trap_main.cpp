// Runs the cycle's haptic calls (read a sample, write a command) on both backends against the
// simulated device, with every heap entry point wrapped at link time, and fails if the host side
// reaches any of them. A plain program: CppUTest's own operator new would clash.
#include <sys/socket.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"
#include "tests/sim/haptic_device/counter_pose.hpp"
#include "tests/support/heap_trap.hpp"

namespace {

// `cycles` cycles of: the device writes a sample (not armed: the far side), the host reads it and
// writes a command (armed). Returns the fresh samples the host read.
unsigned long run(stencil::hal::HapticDevice& host, stencil::sim::SimulatedHapticDevice& device, int cycles) {
  constexpr stencil::hal::MonotonicNs kMs = 1'000'000;
  unsigned long fresh = 0;
  for (int i = 1; i <= cycles; ++i) {
    const stencil::hal::MonotonicNs now = i * kMs;
    device.step(now);
    stencil::hal::HapticSample sample{};
    stencil::test::arm_heap_trap("haptic_allocation_trap");
    const stencil::hal::ReadResult read = host.read_sample(now, sample);
    const stencil::hal::WriteResult written =
        host.write_command({{0.5, -0.25, 1.0}, {10.0, -5.0}, static_cast<std::uint32_t>(i), true});
    stencil::test::disarm_heap_trap();
    fresh += read.status == stencil::hal::ReadStatus::Fresh ? 1 : 0;
    if (written.status == stencil::hal::WriteStatus::Fault) {
      std::fprintf(stderr, "haptic_allocation_trap: a write failed at cycle %d\n", i);
      return 0;
    }
  }
  return fresh;
}

}  // namespace

int main() {
  using namespace stencil;
  const int cycles = 5000;
  // PIO: a memfd window, the simulated device on one mapping and the host on another.
  test::WindowPair windows = test::make_device_window();
  if (windows.device == nullptr) {
    std::fprintf(stderr, "haptic_allocation_trap: %s\n", windows.error.c_str());
    return 1;
  }
  sim::PioDeviceLink pio_link(windows.device->window());
  test::open_host_window(windows);
  if (windows.host == nullptr) {
    std::fprintf(stderr, "haptic_allocation_trap: %s\n", windows.error.c_str());
    return 1;
  }
  sim::SimulatedHapticDevice pio_device(pio_link, test::counter_pose);
  hal::pio_shared_memory::PioHapticDevice pio_host(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange);
  const unsigned long pio_fresh = run(pio_host, pio_device, cycles);

  // SocketCAN: frames through a socketpair.
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) != 0) {
    std::fprintf(stderr, "haptic_allocation_trap: socketpair failed\n");
    return 1;
  }
  hal::socketcan::FdCanChannel host_channel(fds[0]);
  hal::socketcan::FdCanChannel device_channel(fds[1]);
  sim::CanDeviceLink can_link(device_channel);
  sim::SimulatedHapticDevice can_device(can_link, test::counter_pose);
  hal::socketcan::SocketCanHapticDevice can_host(&host_channel, stencil::board::sherline_suzuki::kCentredDeviceRange);
  const unsigned long can_fresh = run(can_host, can_device, cycles);

  const bool ok = stencil::test::trapped_heap_calls() == 0 && pio_fresh > cycles / 2 && can_fresh > cycles / 2;
  std::printf("haptic_allocation_trap: %d cycles per backend, %lu / %lu fresh samples (PIO / CAN), %lu heap calls "
              "inside the host's calls\n",
              cycles, pio_fresh, can_fresh, stencil::test::trapped_heap_calls());
  std::printf("%d passed, %d failed\n", ok ? 1 : 0, ok ? 0 : 1);
  return ok ? 0 : 1;
}
