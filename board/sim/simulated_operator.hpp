// The simulated operator: the hand following the job's script on the simulated device, by the chosen
// transport, or both in a process of their own (over the PIO window). Before each cycle, the device's
// millisecond (a hook of the job's run).
#pragma once

#include <string>

#include "board/sim/device_process.hpp"
#include "board/sim/sim_job.hpp"
#include "board/sim/simulated_device_wiring.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "hal/haptic_device.hpp"
#include "sim/operator/operator_script.hpp"

namespace stencil::board::sim {

class SimulatedOperator final : public runtime::JobHooks {
 public:
  // In lockstep (virtual time) a device process steps with each cycle; in real time it runs on the
  // wall clock, free of the cycle. `job` must outlive the operator.
  SimulatedOperator(const SimJob& job, bool lockstep);

  // Wires the device, and starts its process when the job asks for one (before any thread of this
  // process starts: it forks). Empty when it could; else why not.
  [[nodiscard]] std::string start();

  // What the cycle reads and drives (in this process: the backend's end of the transport).
  [[nodiscard]] hal::HapticDevice& device() { return wiring_.host(); }
  [[nodiscard]] SimulatedDeviceWiring& wiring() { return wiring_; }
  // The device drives no force now.
  [[nodiscard]] bool force_off() const;

  // After the job's duration the hand holds still where the script had got to, while the mill
  // catches up: the same job always ends at the same place.
  bool before_cycle(const runtime::CycleTime& time) override;

 private:
  const SimJob& job_;
  double duration_s_;  // the script's, or the job's
  bool lockstep_;
  stencil::sim::OperatorHand hand_;  // before the wiring: its device samples the handle
  std::string wiring_error_;
  SimulatedDeviceWiring wiring_;
  DeviceProcess process_;
};

}  // namespace stencil::board::sim
