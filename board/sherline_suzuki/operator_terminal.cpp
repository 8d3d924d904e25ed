// The rig's lines to the operator, and the reset typed at the terminal.
#include "board/sherline_suzuki/operator_terminal.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "firmware/core/control/safe_state.hpp"

namespace stencil::board::sherline_suzuki {

void OperatorTerminal::after_machine_update() {
  if (job_.progress && !stop_reported_ && machine_.state() == control::MachineSideState::Stopped) {
    stop_reported_ = true;
    job_.progress(machine_.stop_confirmed()
                      ? "the mill is stopped: spindle and drivers off, confirmed by the controller"
                      : "WARNING: the mill's spindle and drivers could NOT be confirmed off: switch the mill's power off");
  }
}

void OperatorTerminal::on_telemetry(const control::Telemetry& frame) {
  if (job_.progress && frame.safe_reason != last_.safe_reason) {
    job_.progress(frame.safe_reason == control::SafeReason::None
                      ? std::string("force restored; the mill stays stopped (re-homing to resume the cut is not built yet)")
                      : std::string("SAFE STATE: ") + control::safe_reason_name(frame.safe_reason) + " (from " +
                            control::command_source_name(frame.safe_source) + "): no force; the mill is being held and stopped. Hold the handle still near the tool "
                            "and type 'reset' to feel the part again; Ctrl-C ends the run");
  }
  if (job_.progress && frame.paused != last_.paused && (frame.paused || frame.safe_reason == control::SafeReason::None)) {
    job_.progress(frame.paused ? "PAUSED: the tool and the mill are held where they are; type 'resume' to carry on"
                               : "resumed");
  }
  if (job_.progress && frame.reset_requests != last_.reset_requests && frame.last_reset != control::ResetOutcome::Accepted) {
    job_.progress(std::string("reset refused: ") + control::reset_outcome_name(frame.last_reset));
  }
  last_ = frame;
}

void OperatorTerminal::forward_requests(control::CommandRing& commands) {
  // One a pass: a command the full ring cannot take now is typed again by the operator, who sees
  // nothing happen (the ring holds 16 and the cycle drains it every millisecond).
  if (job_.operator_command) {
    if (const std::optional<control::CommandKind> kind = job_.operator_command()) {
      static_cast<void>(commands.push({*kind, 0.0, control::CommandSource::Terminal}));
    }
  }
}

void OperatorTerminal::after_records_pass() {
  if (!job_.progress || std::chrono::steady_clock::now() < next_progress_) {
    return;
  }
  char line[160];
  std::snprintf(line, sizeof line, "cycle %llu, tool at (%.3f, %.3f, %.3f) mm, force %.2f N",
                static_cast<unsigned long long>(last_.cycle), last_.virtual_tip_mm[0], last_.virtual_tip_mm[1],
                last_.virtual_tip_mm[2],
                std::sqrt(last_.force_n[0] * last_.force_n[0] + last_.force_n[1] * last_.force_n[1] +
                          last_.force_n[2] * last_.force_n[2]));
  job_.progress(line);
  next_progress_ += std::chrono::seconds(1);
}

}  // namespace stencil::board::sherline_suzuki
