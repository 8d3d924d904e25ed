// The rig's wiring: its frames, its cycle's configuration and its parts, handed to the runtime, which
// assembles the job and runs it on threads around the real-time cycle; the operator's terminal is a
// hook of the run.
#include "board/sherline_suzuki/rig_job.hpp"

#include <algorithm>

#include "board/sherline_suzuki/operator_terminal.hpp"
#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/runtime/cycle_config.hpp"
#include "firmware/runtime/job.hpp"
#include "firmware/runtime/threaded_run.hpp"
#include "firmware/runtime/stall_message.hpp"

namespace stencil::board::sherline_suzuki {
namespace {

runtime::JobParts parts_of(const RigJob& job) {
  runtime::JobParts parts;
  parts.part = job.part;
  parts.device = job.device;
  parts.machine = job.machine;
  parts.machine_clock = job.machine_clock;
  parts.controller = rig_controller_config(job);
  parts.planner = planner_limits(job.facts);
  parts.period_ns = period_ns(job.facts);
  parts.update_ns = update_ns(job.facts);
  parts.shut_down_bound_ns = 2 * update_ns(job.facts);
  parts.stock = job.stock;
  parts.model_cell_mm = job.facts.stock_model_cell_mm;
  parts.journal = job.journal;
  parts.resume_from = job.resume_from;
  parts.resume_bytes = job.resume_bytes;
  parts.display = job.display;
  parts.interrupted = job.interrupted;
  return parts;
}

// What the run did, from the job's parts once they have stopped.
void fill_result(RigResult& result, const runtime::Job& assembled, const runtime::RunOutcome& outcome) {
  const control::Controller& controller = assembled.controller();
  const control::LoopStatistics& statistics = controller.statistics();
  result.machine_stop_confirmed = assembled.machine().stop_confirmed();
  if (assembled.machine().stalled()) {
    result.machine_stall = runtime::stall_message(assembled.machine().stall());
  }
  if (!outcome.ran) {
    result.error = outcome.error;
  }
  result.cycles = statistics.cycles;
  result.overruns = statistics.overruns;
  result.missed_periods = statistics.missed_periods;
  result.wakeup_latency_us = report::quantiles_of(statistics.wakeup_latency);
  result.compute_us = report::quantiles_of(statistics.compute);
  result.max_force_n = std::max(controller.max_force_n(), result.earlier.max_force_n);  // the whole job
  result.max_offset_mm = std::max(controller.max_offset_mm(), result.earlier.max_offset_mm);
  result.machine_updates = assembled.machine().statistics().updates;
  result.machine_max_lag_mm = assembled.machine().statistics().max_lag_mm;
  result.model_removed_mm3 = assembled.model().ready() ? assembled.model().removed_volume_mm3() : 0.0;
  result.run_s = outcome.run_s;
  result.safe_state = controller.safe_reason();
  result.first_fault = outcome.first_fault;
  result.safe_state_entries = controller.counters().safe_state_entries;
  result.resets_accepted = controller.counters().resets_accepted;
  result.resets_refused = controller.counters().resets_refused;
  result.operator_record = runtime::operator_record_of(assembled, outcome);
}

}  // namespace

motion::MachineFrames rig_frames(const WorkOffset& offset, const RigFacts& facts) {
  Eigen::Vector3d home = offset.home_world_mm;
  home.z() -= offset.tool_stick_out_mm - offset.reference_stick_out_mm;
  return {facts.haptic_to_machine_scale, Eigen::Vector3d::Zero(), home, facts.machine_sign, facts.steps_per_mm};
}

control::ControllerConfig rig_controller_config(const RigJob& job) {
  const RigFacts& f = job.facts;
  const Eigen::Vector3d device_workspace_mm(f.haptic_workspace_mm[0], f.haptic_workspace_mm[1], f.haptic_workspace_mm[2]);
  control::ControllerConfig config = runtime::controller_config(
      {rig_frames(job.offset, f), device_workspace_mm, f.device_reach_margin_mm, f.force_limit_n, f.torque_limit_nmm,
       1.0 / f.haptic_rate_hz, f.virtual_tool_speed_mm_per_s, f.machine_standoff_mm, true});
  // facts.overrun_limit, stale_periods and start_held: the configuration's (the tests' fakes on hosts
  // that are not real-time raise the first two, and their scripted hands, moving from the start, turn
  // the held start off).
  config.start_held = job.facts.start_held;  // no tool motion and no force until the hand is held still near the tool
  config.overrun_limit = job.facts.overrun_limit;
  config.stale_periods = job.facts.stale_periods;
  config.feel.transport_delay_s = job.device_delay_s;  // the wall's feel weighs the force by it
  return config;
}

RigResult run_rig(const RigJob& job, const runtime::PeriodicRunner& runner) {
  RigResult result;
  // A stop asked for while the mill wakes or homes is taken between two of its commands, not after.
  job.machine->abort_on(job.interrupted);
  runtime::Job assembled(parts_of(job), runtime::Timing::RealTime);
  result.earlier = assembled.earlier();
  if (!assembled.error().empty()) {
    result.error = assembled.error();
    return result;
  }
  result.touched_rebuilt = assembled.touched_rebuilt();
  // Nothing turns the spindle on unattended: the operator confirms it once the mill is homed.
  runtime::MachineStart start;
  start.after_homing_within_ns = 2 * update_ns(job.facts);
  start.confirm_spindle = job.confirm_spindle;
  const runtime::StartFailure failure = assembled.start_machine(start);
  if (failure != runtime::StartFailure::None) {
    result.error = assembled.describe(failure);
    return result;
  }
  result.started = true;

  OperatorTerminal terminal(job, assembled.machine());
  runtime::JobHooks* const hooks[] = {&terminal};
  runtime::ThreadedRun options;
  // The stop that ends every run ends the loop; a fault's safe state keeps the cycle running (zero
  // force) for a reset, never an automatic one.
  options.safe_state_ends = runtime::SafeStateEnds::AfterStop;
  options.stop_after_s = job.duration_s;
  options.settle_ns = 3 * update_ns(job.facts);  // two machine updates: the safe state reaches the mill (hold, then stop)
  options.prepare_machine_thread = job.prepare_machine_thread;
  const runtime::RunOutcome outcome = runtime::run_on_threads(assembled, runner, hooks, options);
  fill_result(result, assembled, outcome);
  return result;
}

}  // namespace stencil::board::sherline_suzuki
