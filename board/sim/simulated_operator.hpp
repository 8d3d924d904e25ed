// The simulated operator: the hand following the job's script on the simulated device, by the chosen
// transport, or both in a process of their own (over the PIO window). Before each cycle, the device's
// millisecond (a hook of the job's run).
#pragma once

#include <optional>
#include <string>

#include "board/sim/device_process.hpp"
#include "board/sim/sim_job.hpp"
#include "board/sim/simulated_device_wiring.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "hal/haptic_device.hpp"
#include "sim/operator/hand_device_model.hpp"
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
  void move_dynamic_hand(const runtime::CycleTime& time, double script_s);

  const SimJob& job_;
  double duration_s_;  // the script's, or the job's
  bool lockstep_;
  stencil::sim::OperatorHand hand_;  // before the wiring: its device samples the handle
  // With a dynamic hand (SimJob::hand), the arm and the handle's dynamics, from the first cycle: the
  // script is where the hand means to go, and hand_ only carries the handle's position to the device.
  std::optional<stencil::sim::HandDeviceModel> dynamics_;
  std::string wiring_error_;
  SimulatedDeviceWiring wiring_;
  DeviceProcess process_;
};

}  // namespace stencil::board::sim
