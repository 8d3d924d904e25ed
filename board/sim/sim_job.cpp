// The simulation board: its frames and cycle configuration, and its wiring. A job's parts (the
// simulated machine behind the CY545 driver, the operator's hand on the simulated device or a
// replayed journal's device) are built here and handed to the runtime, which assembles the job and
// runs it, in virtual time (run_fast) or on threads in real time (run_realtime); the fault to inject,
// the replay's comparison, the machined part's legs and the job's end are hooks of its run.
#include "board/sim/sim_job.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>

#include "board/sim/fault_injector.hpp"
#include "board/sim/job_end.hpp"
#include "board/sim/journal_replay.hpp"
#include "board/sim/linuxcnc_wiring.hpp"
#include "board/sim/mill_wiring.hpp"
#include "board/sim/sim_result.hpp"
#include "board/sim/simulated_operator.hpp"
#include "firmware/runtime/cycle_config.hpp"
#include "firmware/runtime/job.hpp"
#include "firmware/runtime/threaded_run.hpp"
#include "firmware/runtime/virtual_time_run.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/haptic_device/replay_haptic_device.hpp"
#include "sim/mill/machined_part.hpp"

namespace stencil::board::sim {
// The period, the update, the model's cells and the planner's limits: the configured rig's (sim_facts.hpp).

motion::MachineFrames frames(const SimRig& rig) {
  // Every axis counts into the workspace from its switch, so the world runs against all three.
  const rig::RigFacts& f = rig.facts;
  return {f.haptic_to_machine_scale, Eigen::Vector3d::Zero(),
          Eigen::Vector3d(rig.home_world_mm[0], rig.home_world_mm[1], rig.home_world_mm[2]), f.machine_sign, f.steps_per_mm};
}

motion::MachineFrames true_frames(const SimRig& rig) {
  motion::MachineFrames truth = frames(rig);
  truth.steps_per_mm = rig.mill_truth.steps_per_mm;
  truth.machine_sign = rig.mill_truth.machine_sign;
  return truth;
}

stencil::sim::StockBox default_stock(const tables::PartTables& part) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e300), high = Eigen::Vector3d::Constant(-1e300);
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    for (const tables::PackedPoint& v : part.triangles[t].vertices) {
      const Eigen::Vector3d p(v.x_mm, v.y_mm, v.z_mm);
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  }
  const Eigen::Vector3d workspace(part.header.workspace_mm[0], part.header.workspace_mm[1], part.header.workspace_mm[2]);
  const Eigen::Vector3d margin(2.0, 2.0, 0.0);
  return {(low - margin).cwiseMax(Eigen::Vector3d::Zero()).cwiseProduct(Eigen::Vector3d(1, 1, 0)),
          (high + margin + Eigen::Vector3d(0, 0, 1.0)).cwiseMin(workspace)};
}

control::ControllerConfig controller_config(bool realtime, const SimRig& rig) {
  const rig::RigFacts& f = rig.facts;
  const Eigen::Vector3d device_workspace_mm(f.haptic_workspace_mm[0], f.haptic_workspace_mm[1], f.haptic_workspace_mm[2]);
  // Overruns count in real time only: in virtual time lateness means nothing.
  return runtime::controller_config({frames(rig), device_workspace_mm, f.device_reach_margin_mm, f.force_limit_n,
                                     f.torque_limit_nmm, 1.0 / f.haptic_rate_hz, f.virtual_tool_speed_mm_per_s,
                                     f.machine_standoff_mm, realtime});
}

std::function<double(double, double)> touch_tip_of(const tables::PartTables& part, const stencil::sim::StockBox& stock) {
  auto grid = std::make_shared<stencil::sim::StockZmap>(stock, 0.05);
  auto tips = std::make_shared<std::vector<double>>(
      stencil::sim::lowest_tips(*grid, stencil::sim::part_top_heights(part, *grid), stencil::sim::ToolProfile::of(part.tool.spec)));
  return [grid, tips](double x, double y) {
    const int column = std::clamp(static_cast<int>((x - grid->box().low_mm.x()) / grid->cell_mm()), 0, grid->columns() - 1);
    const int row = std::clamp(static_cast<int>((y - grid->box().low_mm.y()) / grid->cell_mm()), 0, grid->rows() - 1);
    return (*tips)[static_cast<std::size_t>(row) * static_cast<std::size_t>(grid->columns()) + static_cast<std::size_t>(column)];
  };
}

namespace {

// The board's parts, handed to the runtime: the cycle reads `device`.
runtime::JobParts parts_of(const SimJob& job, SimMachine& mill, hal::HapticDevice& device, bool realtime) {
  runtime::JobParts parts;
  parts.part = job.part;
  parts.device = &device;
  parts.machine = &mill.link();
  parts.machine_clock = &mill.clock();
  parts.controller = controller_config(realtime, job.rig);
  // The wall's feel weighs the force by the link's delay, as the rig expects it for that link.
  parts.controller.feel.transport_delay_s = job.transport == HapticTransport::Pio   ? hal::kPioCommandDelayS
                                            : job.transport == HapticTransport::Can ? hal::kCanCommandDelayS
                                                                                    : 0.0;
  parts.planner = rig::planner_limits(job.rig.facts);
  parts.period_ns = rig::period_ns(job.rig.facts);
  parts.update_ns = rig::update_ns(job.rig.facts);
  parts.shut_down_bound_ns = runtime::kUpdateBoundUpdates * parts.update_ns;
  parts.stock = {job.stock.low_mm, job.stock.high_mm};
  parts.model_cell_mm = job.rig.facts.stock_model_cell_mm;
  parts.journal = job.journal;
  parts.resume_from = job.resume_from;
  parts.resume_bytes = job.resume_bytes;
  // A resumed job's mill starts from the stock the journal says it cut.
  parts.recorded_leg = [&mill](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    mill.machined().cut_recorded_leg(from, to);
  };
  parts.display = job.display;
  parts.interrupted = job.interrupted;
  return parts;
}

// In virtual time: the fault to inject, then the replay or the hand, then the job's end; after each
// machine update, the machined part.
SimResult run_virtual(const SimJob& job, runtime::Job& assembled, MillWiring& mill, SimulatedOperator& hand,
                      stencil::sim::ReplayHapticDevice& replay_device, SimResult& result,
                      std::chrono::steady_clock::time_point wall_start) {
  FaultInjector fault(job.fault, hand.wiring(), mill.fake(), assembled.controller(), rig::period_ns(job.rig.facts));
  std::optional<JournalReplay> replay;
  if (job.replay != nullptr) {
    static const std::vector<control::CommandEvent> kNone;
    replay.emplace(*job.replay, job.replay_commands != nullptr ? *job.replay_commands : kNone, replay_device,
                   assembled.controller(), assembled.rings().commands);
  }
  JobEnd end(job, assembled.controller());
  runtime::JobHooks* const device_side = replay ? static_cast<runtime::JobHooks*>(&*replay) : &hand;
  runtime::JobHooks* const hooks[] = {&fault, device_side, &end, &mill};
  const runtime::VirtualTimeRun options{job.pace, wall_start, [&hand] { return hand.force_off(); }};
  const runtime::RunOutcome outcome = runtime::run_on_virtual_time(assembled, hooks, options);
  const hal::MonotonicNs end_ns = mill.clock().now_ns();
  mill.leave(result, assembled.machine().stop_confirmed(), end_ns);
  mill.machined().flush();
  result.complete = end.complete();
  result.fault_kind = fault.injected();
  result.fault_injected_s = fault.injected_s();
  if (replay) {
    result.replay_cycles = replay->cycles();
    result.replay_mismatches = replay->mismatches();
    result.replay_first_mismatch = replay->first_mismatch();
    result.replay_recorded_reason = replay->recorded_reason();
    result.replay_commands_not_given = replay->commands_not_replayed();
  }
  fill_result(result, assembled, outcome, mill, false, wall_start);
  return result;
}

// In real time: the hand before each cycle (unless the device runs in a process of its own, on the
// wall clock), the job's end, and the machined part after each update; then the fake stops
// answering, once the machine side has stopped the mill.
SimResult run_threads(const SimJob& job, runtime::Job& assembled, SimMachine& mill, SimulatedOperator& hand,
                      const runtime::PeriodicRunner& runner, SimResult& result,
                      std::chrono::steady_clock::time_point wall_start) {
  JobEnd end(job, assembled.controller());
  runtime::JobHooks* const hooks[] = {&hand, &end, &mill};
  runtime::ThreadedRun options;
  options.safe_state_ends = runtime::SafeStateEnds::Any;
  options.settle_ns = 2 * rig::update_ns(job.rig.facts);  // one more update, so a safe state reaches the mill (hold, then stop)
  const runtime::RunOutcome outcome = runtime::run_on_threads(assembled, runner, hooks, options);
  mill.stop_answering();
  mill.leave(result, assembled.machine().stop_confirmed(), hal::posix_clock::monotonic_now_ns());
  if (!outcome.ran) {
    result.started = false;
    result.error = outcome.error;
    return result;
  }
  mill.machined().flush();
  result.complete = end.complete();
  fill_result(result, assembled, outcome, mill, true, wall_start);
  return result;
}

// `cy545`: the same machine when it is the fake CY545's (virtual time needs it: its fault hooks and clock).
SimResult run_on(const SimJob& job, const runtime::PeriodicRunner* runner, SimMachine& mill, MillWiring* cy545) {
  const bool realtime = runner != nullptr;
  const auto wall_start = std::chrono::steady_clock::now();
  SimResult result;
  result.standoff_mm = job.rig.facts.machine_standoff_mm;
  if (!mill.error().empty()) {
    result.error = mill.error();
    return result;
  }
  // The device, and its process when there is one: forked now, before any thread of this one starts.
  SimulatedOperator hand(job, !realtime);
  result.error = hand.start();
  if (!result.error.empty()) {
    return result;
  }
  // A replay's cycle reads the journal's device; any other's the simulated one.
  stencil::sim::ReplayHapticDevice replay_device;
  hal::HapticDevice& cycle_device = job.replay != nullptr ? static_cast<hal::HapticDevice&>(replay_device) : hand.device();
  runtime::Job assembled(parts_of(job, mill, cycle_device, realtime),
                         realtime ? runtime::Timing::RealTime : runtime::Timing::Virtual);
  result.earlier = assembled.earlier();
  if (!assembled.error().empty()) {
    result.error = assembled.error();
    return result;
  }
  result.touched_rebuilt = assembled.touched_rebuilt();
  if (realtime) {
    mill.start_answering();
  }
  const runtime::StartFailure failure = assembled.start_machine({});
  if (failure != runtime::StartFailure::None) {
    result.error = failure == runtime::StartFailure::HomingNotRecorded
                       ? assembled.describe(failure)
                       : std::string("the machine did not start: ") + mill.link_error();
    return result;
  }
  result.started = true;
  result.rss_after_setup_kb = resident_kb();
  if (job.replay == nullptr) {
    for (const control::Command& command : job.opening_commands) {
      if (!assembled.rings().commands.push(command)) {
        result.error = "the opening commands do not fit the command ring";
        return result;
      }
    }
  }
  mill.arm();
  if (realtime) {
    return run_threads(job, assembled, mill, hand, *runner, result, wall_start);
  }
  return run_virtual(job, assembled, *cy545, hand, replay_device, result, wall_start);
}

SimResult run_job(const SimJob& job, const runtime::PeriodicRunner* runner) {
  if (job.linuxcnc && runner == nullptr) {
    SimResult refused;
    refused.error = "a LinuxCNC mill runs in real time only (--speed 1): LinuxCNC keeps the wall clock's time";
    return refused;
  }
  if (job.linuxcnc) {
    LinuxcncWiring mill(job);
    return run_on(job, runner, mill, nullptr);
  }
  MillWiring mill(job, runner != nullptr);
  return run_on(job, runner, mill, &mill);
}

}  // namespace

SimResult run_fast(const SimJob& job) { return run_job(job, nullptr); }

SimResult run_realtime(const SimJob& job, const runtime::PeriodicRunner& runner) { return run_job(job, &runner); }

}  // namespace stencil::board::sim
