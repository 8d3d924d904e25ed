// SimulatedHapticDevice: the device's side of the haptic exchange, simulated: writes pose samples from
// a pose source, reads the host's commands, and keeps the device's own host-heartbeat watchdog (it
// zeroes the force when the host stops beating). Works over either backend's DeviceSideLink. Not
// real-time code; thread-safe (step() may run on its own thread, see simulated_device_thread.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>

#include "hal/clock.hpp"
#include "hal/haptic_device.hpp"
#include "hal/heartbeat_watchdog.hpp"
#include "sim/haptic_device/device_side_link.hpp"

namespace stencil::sim {

struct SimulatedPose {
  double position_mm[3];
  double angles_rad[2];
};

// Where the handle is for the sample with this counter, at this time.
using PoseSource = std::function<SimulatedPose(std::uint32_t sample_counter, hal::MonotonicNs now_ns)>;

inline constexpr hal::MonotonicNs kDefaultHostWatchdogNs = 20'000'000;  // both wires' kHostWatchdogMs

// What the device's motors drive now, and why.
struct DeviceOutput {
  double force_n[3];
  double torque_nmm[2];
  bool force_applied;        // a command with enable on, accepted, watchdog not tripped
  bool watchdog_tripped;     // the host heartbeat froze: force zero until re-armed (enable off, then on)
  bool last_command_refused; // the newest thing the host sent was refused
  std::uint32_t last_cycle_counter;
  std::uint64_t commands_accepted;
  std::uint64_t commands_refused;
  std::uint64_t watchdog_trips;
  std::uint32_t samples_written;
};

class SimulatedHapticDevice {
 public:
  // `link` must outlive this object.
  SimulatedHapticDevice(DeviceSideLink& link, PoseSource source,
                        hal::MonotonicNs host_watchdog_ns = kDefaultHostWatchdogNs);

  // One device cycle at now_ns: take the host's commands, run the watchdog, decide the output, write
  // one pose sample (counter + 1, heartbeat + 1). Does nothing while frozen.
  void step(hal::MonotonicNs now_ns);

  // A frozen device stops everything (no pose, no heartbeat, no command read): a hung controller.
  void set_frozen(bool frozen);
  // Sets or clears hal::haptic_status::kDeviceFault in the samples.
  void set_device_fault(bool fault);

  [[nodiscard]] DeviceOutput output() const;

 private:
  void zero_output();

  DeviceSideLink& link_;
  PoseSource source_;
  mutable std::mutex mutex_;
  hal::HeartbeatWatchdog host_watchdog_;
  DeviceCommand command_{};
  bool have_command_ = false;
  bool frozen_ = false;
  bool device_fault_ = false;
  std::uint32_t sample_counter_ = 0;
  std::uint32_t heartbeat_ = 0;
  DeviceOutput output_{};
};

// A pose source that moves linearly through waypoints, one every `segment_ns`, then holds the last.
[[nodiscard]] PoseSource scripted_trajectory(const SimulatedPose* waypoints, std::size_t count,
                                             hal::MonotonicNs start_ns, hal::MonotonicNs segment_ns);

}  // namespace stencil::sim
