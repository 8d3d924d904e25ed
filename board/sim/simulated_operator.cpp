// The simulated operator's hand on the device, cycle by cycle.
#include "board/sim/simulated_operator.hpp"

#include <cerrno>
#include <cstring>

#include <algorithm>

namespace stencil::board::sim {
namespace {

// The hand where the script starts.
stencil::sim::OperatorHand hand_at_start(const stencil::sim::OperatorScript& script) {
  stencil::sim::OperatorHand hand;
  hand.handle_mm = script.position_at(0.0);
  return hand;
}

}  // namespace

SimulatedOperator::SimulatedOperator(const SimJob& job, bool lockstep)
    : job_(job),
      duration_s_(job.duration_s > 0.0 ? job.duration_s : job.script.duration_s()),
      lockstep_(lockstep),
      hand_(hand_at_start(job.script)),
      wiring_(job.transport, rig::programs_device_range(job.rig.facts), hand_, wiring_error_) {}

std::string SimulatedOperator::start() {
  if (!wiring_.ready()) {
    return "the simulated device's link: " + wiring_error_;
  }
  if (job_.device_process_log == nullptr) {
    return "";
  }
  if (job_.hand.mass_kg > 0.0) {
    return "the device's own process moves the placed hand only, not a dynamic one";
  }
  if (job_.transport != HapticTransport::Pio || job_.fault.kind != FaultKind::None) {
    return "the device runs in its own process only over the PIO window, and with no fault injected";
  }
  if (!process_.start(*wiring_.simulated(), hand_, job_.script, duration_s_, lockstep_, job_.device_process_log)) {
    return std::string("the device's process could not be started: ") + std::strerror(errno);
  }
  return "";
}

void SimulatedOperator::move_dynamic_hand(const runtime::CycleTime& time, double script_s) {
  if (!dynamics_) {
    dynamics_.emplace(stencil::sim::DeviceParameters{}, job_.hand, time.now_ns, hand_.handle_mm);
  }
  // The hand means to be where the script is, moving as the script moves over the next period (the
  // arm's damper pulls towards that velocity).
  const double period_s = static_cast<double>(rig::period_ns(job_.rig.facts)) / 1e9;
  const Eigen::Vector3d intent = job_.script.position_at(script_s);
  const Eigen::Vector3d ahead = job_.script.position_at(std::min(script_s + period_s, duration_s_));
  dynamics_->set_intent(intent, (ahead - intent) / period_s);
  // What the motors drove over the period just ended (the transport's own code and timing are the
  // wiring's: no delay is added here), held until now.
  static_cast<void>(dynamics_->command_force(dynamics_->now_ns(), wiring_.rendered_force()));
  dynamics_->advance_to(time.now_ns);
  hand_.handle_mm = dynamics_->position_mm();
}

bool SimulatedOperator::force_off() const { return process_.running() ? process_.force_off() : wiring_.force_off(); }

bool SimulatedOperator::before_cycle(const runtime::CycleTime& time) {
  const double script_s = std::min(time.t_s, duration_s_);
  if (process_.running()) {
    if (lockstep_) {
      static_cast<void>(process_.step(time.now_ns, script_s));  // no answer: no fresh sample, as from a hung device
    }
    return true;
  }
  if (job_.hand.mass_kg > 0.0) {
    move_dynamic_hand(time, script_s);
  } else {
    hand_.step(job_.script.position_at(script_s), wiring_.rendered_force());
  }
  wiring_.device_cycle(hand_, job_.script.angles_at(script_s), time.now_ns);
  return true;
}

}  // namespace stencil::board::sim
