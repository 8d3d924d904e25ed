// OperatorTerminal: what the rig's run tells the operator at the terminal (the mill's stop, each safe
// state and its way out, a refused reset, a line about every second) and the reset typed there, as
// hooks of the job's run: the machine thread's line, the records thread's.
#pragma once

#include <chrono>

#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/machine_side.hpp"
#include "firmware/runtime/job_hooks.hpp"

namespace stencil::board::sherline_suzuki {

class OperatorTerminal final : public runtime::JobHooks {
 public:
  // `job` and `machine` must outlive the terminal.
  OperatorTerminal(const RigJob& job, const control::MachineSide& machine)
      : job_(job), machine_(machine), next_progress_(std::chrono::steady_clock::now() + std::chrono::seconds(1)) {}

  void after_machine_update() override;
  void on_telemetry(const control::Telemetry& frame) override;
  void forward_requests(control::CommandRing& commands) override;
  void after_records_pass() override;

 private:
  const RigJob& job_;
  const control::MachineSide& machine_;
  bool stop_reported_ = false;  // the machine thread's
  control::Telemetry last_{};   // the records thread's, as every member below
  std::chrono::steady_clock::time_point next_progress_;
};

}  // namespace stencil::board::sherline_suzuki
