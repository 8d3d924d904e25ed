// The rig's run: the parts built once, three threads around the cycle, a safe way out.
#include "board/sherline_suzuki/rig_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/loop_statistics.hpp"
#include "firmware/core/control/machine_side.hpp"
#include "firmware/services/journal/journal_drain.hpp"

namespace stencil::board::sherline_suzuki {
namespace {

// kPeriodNs and kUpdateNs: rig_facts.hpp.
constexpr double kModelCellMm = kRig.stock_model_cell_mm;
constexpr double kVirtualToolSpeedMmPerS = kRig.virtual_tool_speed_mm_per_s;

}  // namespace

motion::MachineFrames rig_frames(const WorkOffset& offset) {
  Eigen::Vector3d home = offset.home_world_mm;
  home.z() -= offset.tool_stick_out_mm - offset.reference_stick_out_mm;
  return {kRig.haptic_to_machine_scale, Eigen::Vector3d::Zero(), home, kRig.machine_sign, kRig.steps_per_mm};
}

control::ControllerConfig rig_controller_config(const RigJob& job) {
  const motion::MachineFrames frames = rig_frames(job.offset);
  control::ControllerConfig config;
  config.frames = frames;
  config.contact.device_mm_per_world_mm = kRig.haptic_to_machine_scale;
  config.haptic.device_mm_per_world_mm = kRig.haptic_to_machine_scale;
  config.haptic.max_force_n = kRig.force_limit_n;
  config.haptic.max_torque_nmm = kRig.torque_limit_nmm;
  config.period_s = 1.0 / kRig.haptic_rate_hz;
  config.device_low_mm = Eigen::Vector3d::Constant(-kRig.device_reach_margin_mm);
  config.device_high_mm = Eigen::Vector3d(kRig.haptic_workspace_mm[0] + kRig.device_reach_margin_mm,
                                          kRig.haptic_workspace_mm[1] + kRig.device_reach_margin_mm,
                                          kRig.haptic_workspace_mm[2] + kRig.device_reach_margin_mm);
  config.home_tip_mm = frames.home_world_mm;
  config.start_held = job.start_held;  // no tool motion and no force until the hand is held still near the tool
  config.count_overruns = true;
  config.overrun_limit = job.overrun_limit;
  config.stale_periods = job.stale_periods;
  config.max_axis_move_mm = kVirtualToolSpeedMmPerS * config.period_s;
  config.max_total_move_mm = kVirtualToolSpeedMmPerS * config.period_s;
  return config;
}

RigResult run_rig(const RigJob& job, const runtime::PeriodicRunner& runner) {
  RigResult result;
  const tables::PartTables& part = *job.part;
  const motion::MachineFrames frames = rig_frames(job.offset);

  auto rings = std::make_unique<control::CycleRingStorage>();
  journal::JournalDrain records{job.journal, rings->commands};
  records.show_on(job.display);
  control::DisplayCommands display_commands;

  const control::ControllerConfig config = rig_controller_config(job);
  auto controller = std::make_unique<control::Controller>(
      part, *job.device, rings->rings(), config);
  if (!controller->ready()) {
    result.error = "the tables' tool could not be grown for the touched set";
    return result;
  }
  const motion::PlannerLimits limits = kPlannerLimits;
  auto machine = std::make_unique<control::MachineSide>(part, *job.machine, frames, limits, rings->machine, rings->machine_events);
  std::vector<float> model_cells(control::CommandedStock::cells_needed(job.stock, kModelCellMm));
  control::CommandedStock model(job.stock, kModelCellMm, part.tool.spec, model_cells);
  if (model.ready()) {
    machine->keep_stock_model(&model);
  }
  std::unique_ptr<journal::MachineJournal> machine_journal;
  if (job.journal != nullptr) {
    machine_journal = std::make_unique<journal::MachineJournal>(*job.journal);
    machine->record_to(machine_journal.get());
  }
  if (!job.resume_from.empty()) {
    const journal::HistoryRebuild rebuild{
        [&](const Eigen::Vector3d& tip) { controller->recall_touched(tip); },
        [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
          if (model.ready()) {
            model.cut(from, to);
          }
        }};
    std::string history_error;
    if (!journal::read_job_history(job.resume_from, part.header.crc32, part.header.triangle_count, frames, rebuild,
                                   result.earlier, history_error, job.resume_bytes)) {
      result.error = "--resume: " + history_error;
      return result;
    }
    if (job.display != nullptr) {
      job.display->seed_touched(controller->touched());  // before the cycle runs: no race
    }
    result.touched_rebuilt = static_cast<std::uint32_t>(controller->touched().count());
  }
  hal::Clock& clock = *job.machine_clock;
  // A stop asked for while the mill wakes or homes is taken between two of its commands, not after.
  job.machine->abort_on(job.interrupted);
  // Wake-up and spindle in seconds; homing as long as the link says it can take from anywhere.
  if (!machine->home(clock.now_ns() + job.machine->homing_bound_ns() + 20'000'000'000)) {
    result.error = machine->record_failed() ? "the machine did not start: its homing could not be journalled: " + job.journal->error()
                                            : "the machine did not start (wake, home)";
    return result;
  }
  if (job.confirm_spindle && !job.confirm_spindle()) {
    static_cast<void>(job.machine->stop(clock.now_ns() + 2 * kUpdateNs));  // drivers off: nothing runs unattended
    result.error = "the spindle was not confirmed: nothing was cut";
    return result;
  }
  if (!machine->start_spindle(clock.now_ns() + 2 * kUpdateNs)) {
    result.error = "the machine did not start (spindle on)";
    return result;
  }
  result.started = true;

  std::atomic<bool> stop{false};
  std::atomic<hal::MonotonicNs> start_ns{0};
  std::atomic<control::SafeReason> first_fault{control::SafeReason::None};
  std::atomic<bool> stop_asked{false};
  std::thread machine_thread([&] {
    if (job.prepare_machine_thread) {
      job.prepare_machine_thread();  // its priority: below the cycle, above the records thread
    }
    hal::MonotonicNs next = clock.now_ns();
    bool stop_reported = false;
    while (!stop.load()) {
      clock.sleep_until_ns(next);
      // Bounded from the update's actual start: the CY545's commands and their settles can make an
      // update outlast its period (the mill falls behind and the backlog slows the virtual tool).
      machine->update(std::max(next, clock.now_ns()) + 3 * kUpdateNs);
      if (job.progress && !stop_reported && machine->state() == control::MachineSideState::Stopped) {
        stop_reported = true;
        job.progress(machine->stop_confirmed()
                         ? "the mill is stopped: spindle and drivers off, confirmed by the controller"
                         : "WARNING: the mill's spindle and drivers could NOT be confirmed off: switch the mill's power off");
      }
      if (job.display != nullptr && model.ready()) {
        job.display->on_machine(machine->statistics().last_lag_mm, model);
      }
      next = std::max(next + kUpdateNs, clock.now_ns());
    }
  });
  std::thread records_thread([&] {
    auto next_progress = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    control::Telemetry last{};
    bool stop_sent = false;
    while (!stop.load()) {
      records.drain(rings->journal);
      records.sync_if_due();
      control::Telemetry frame{};
      while (rings->telemetry.pop(frame)) {
        if (job.display != nullptr) {
          job.display->on_telemetry(frame);
        }
        if (job.progress && frame.safe_reason != last.safe_reason) {
          job.progress(frame.safe_reason == control::SafeReason::None
                           ? std::string("force restored; the mill stays stopped (re-homing to resume the cut is not built yet)")
                           : std::string("SAFE STATE: ") + control::safe_reason_name(frame.safe_reason) +
                                 ": no force; the mill is being held and stopped. Hold the handle still near the tool "
                                 "and type 'reset' to feel the part again; Ctrl-C ends the run");
        }
        if (job.progress && frame.reset_requests != last.reset_requests && frame.last_reset != control::ResetOutcome::Accepted) {
          job.progress(std::string("reset refused: ") + control::reset_outcome_name(frame.last_reset));
        }
        last = frame;
      }
      if (!stop_sent) {
        display_commands.forward(job.display, rings->commands);
      }
      if (!stop_sent && job.reset_requested && job.reset_requested()) {
        static_cast<void>(rings->commands.push({control::CommandKind::Reset}));
      }
      // The run ends through the cycle's own stop (this thread is the command ring's one producer):
      // on SIGINT/SIGTERM, or when the duration is up.
      const hal::MonotonicNs started = start_ns.load();
      const bool time_up = job.duration_s > 0.0 && started != 0 &&
                           static_cast<double>(clock.now_ns() - started) / 1e9 >= job.duration_s;
      if (!stop_sent && ((job.interrupted != nullptr && job.interrupted->load()) || time_up)) {
        stop_asked.store(true, std::memory_order_release);
        stop_sent = rings->commands.push({control::CommandKind::Stop});
      }
      if (job.progress && std::chrono::steady_clock::now() >= next_progress) {
        char line[160];
        std::snprintf(line, sizeof line, "cycle %llu, tool at (%.3f, %.3f, %.3f) mm, force %.2f N",
                      static_cast<unsigned long long>(last.cycle), last.virtual_tip_mm[0], last.virtual_tip_mm[1],
                      last.virtual_tip_mm[2],
                      std::sqrt(last.force_n[0] * last.force_n[0] + last.force_n[1] * last.force_n[1] +
                                last.force_n[2] * last.force_n[2]));
        job.progress(line);
        next_progress += std::chrono::seconds(1);
      }
      // Or less: a target the machine thread queued wakes this thread, which writes it at once, so
      // the machine side sends it at its next update.
      records.wait(std::chrono::milliseconds(50));
    }
  });

  std::string runner_error;
  const bool ran = runner(
      kPeriodNs, stop,
      [&](hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns) {
        if (start_ns.load(std::memory_order_relaxed) == 0) {
          start_ns.store(deadline_ns);
        }
        const control::CycleStatus status = controller->step(now_ns, deadline_ns);
        controller->finish(clock.now_ns(), deadline_ns + kPeriodNs);
        const control::SafeReason reason = controller->safe_reason();
        if (reason != control::SafeReason::None && reason != control::SafeReason::Stopped &&
            first_fault.load(std::memory_order_relaxed) == control::SafeReason::None) {
          first_fault.store(reason, std::memory_order_relaxed);
        }
        // The stop that ends every run ends the loop; a fault's safe state keeps the cycle running
        // (zero force) for a reset, never an automatic one.
        // (A stop in a fault's safe state keeps the fault as the latched reason, so the loop ends
        // on the stop having been asked, once the cycle is safe.)
        return !(status == control::CycleStatus::SafeState && stop_asked.load(std::memory_order_acquire));
      },
      runner_error);
  // Two machine updates, so the safe state reaches the mill (hold, then stop), then all stop.
  std::this_thread::sleep_for(std::chrono::nanoseconds(3 * kUpdateNs));
  stop.store(true);
  machine_thread.join();
  records_thread.join();
  records.drain(rings->journal);
  // The runner refused before the cycle ran (or the cycle never reached the machine side): the
  // machine is stopped here all the same.
  machine->shut_down(clock.now_ns() + 2 * kUpdateNs);
  result.machine_stop_confirmed = machine->stop_confirmed();
  if (!ran) {
    result.error = runner_error;
  }
  const control::LoopStatistics& statistics = controller->statistics();
  result.cycles = statistics.cycles;
  result.overruns = statistics.overruns;
  result.missed_periods = statistics.missed_periods;
  result.wakeup_p99_us = statistics.wakeup_latency.quantile_us(0.99);
  result.wakeup_p999_us = statistics.wakeup_latency.quantile_us(0.999);
  result.wakeup_max_us = static_cast<double>(statistics.wakeup_latency.max_ns()) / 1000.0;
  result.compute_p99_us = statistics.compute.quantile_us(0.99);
  result.compute_max_us = static_cast<double>(statistics.compute.max_ns()) / 1000.0;
  result.max_force_n = std::max(controller->max_force_n(), result.earlier.max_force_n);  // the whole job
  result.max_offset_mm = std::max(controller->max_offset_mm(), result.earlier.max_offset_mm);
  result.machine_updates = machine->statistics().updates;
  result.machine_max_lag_mm = machine->statistics().max_lag_mm;
  result.model_removed_mm3 = model.ready() ? model.removed_volume_mm3() : 0.0;
  result.run_s = start_ns.load() != 0 ? static_cast<double>(clock.now_ns() - start_ns.load()) / 1e9 : 0.0;
  result.safe_state = controller->safe_reason();
  result.first_fault = first_fault.load();
  result.safe_state_entries = controller->counters().safe_state_entries;
  result.resets_accepted = controller->counters().resets_accepted;
  result.resets_refused = controller->counters().resets_refused;
  return result;
}

}  // namespace stencil::board::sherline_suzuki
