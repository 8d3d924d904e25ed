// The simulated device in a process of its own (over the PIO window, which a memfd mapping shares
// across fork()): the operator's hand and the device's millisecond run there, so that when the
// controller's process dies, even by SIGKILL, the device's own host heartbeat watchdog is what zeroes
// the force, as on the rig.
//
// In real time the device runs on the wall clock, free of the cycle. On the virtual clock it runs in
// lockstep: each cycle the controller's process hands it the cycle's time and waits for its sample,
// so the job stays deterministic; once the controller is gone it carries on on the wall clock.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>

#include <sys/types.h>

#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "sim/operator/operator_script.hpp"

namespace stencil::board::sim {

// Shared between the two processes (an anonymous MAP_SHARED page): the lockstep's handshake and
// what the device drives.
struct DeviceProcessShared {
  std::atomic<std::uint64_t> go{0};    // the controller: step for this cycle (1, 2, ...)
  std::atomic<std::uint64_t> done{0};  // the device: stepped for it
  std::atomic<std::int64_t> now_ns{0};  // the cycle's virtual time
  std::atomic<double> script_s{0.0};    // where the hand's script is
  std::atomic<bool> force_applied{false};
  std::atomic<double> force_n[3]{};
};

class DeviceProcess {
 public:
  DeviceProcess() = default;
  DeviceProcess(const DeviceProcess&) = delete;
  DeviceProcess& operator=(const DeviceProcess&) = delete;
  ~DeviceProcess() { stop(); }

  // Forks (call before any thread starts). The child steps `device` with `hand` following `script`
  // (held still after `duration_s`); once its parent is gone it writes to `log` how long the force
  // took to reach zero and exits (0: within a second, 1: not). False with errno on failure.
  [[nodiscard]] bool start(stencil::sim::SimulatedHapticDevice& device, stencil::sim::OperatorHand& hand,
                           const stencil::sim::OperatorScript& script, double duration_s, bool lockstep, std::FILE* log);

  // Lockstep: the device's millisecond for the cycle at now_ns; false if it did not answer within a
  // second (the cycle then reads no fresh sample, as from a hung device).
  [[nodiscard]] bool step(std::int64_t now_ns, double script_s);

  [[nodiscard]] bool running() const { return child_ > 0; }
  [[nodiscard]] bool force_off() const;
  [[nodiscard]] Eigen::Vector3d force_n() const;

  // Stops the child (SIGTERM) and reaps it.
  void stop();

 private:
  pid_t child_ = -1;
  DeviceProcessShared* shared_ = nullptr;
};

}  // namespace stencil::board::sim
