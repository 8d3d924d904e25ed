// The virtual-time interleave of the cycle and the machine side: which runs when is what makes the
// records the same each time, so the order of everything here is part of its behaviour.
#include "firmware/runtime/virtual_time_run.hpp"

#include <algorithm>
#include <thread>

namespace stencil::runtime {
namespace {

class VirtualTimeLoop {
 public:
  VirtualTimeLoop(Job& job, std::span<JobHooks* const> hooks, const VirtualTimeRun& options)
      : job_(job), hooks_(hooks), options_(options), period_ns_(job.parts().period_ns) {}

  RunOutcome run() {
    hal::Clock& clock = job_.machine_clock();
    start_ns_ = (clock.now_ns() / period_ns_ + 1) * period_ns_;
    cycle_ns_ = start_ns_;
    next_update_ns_ = start_ns_;
    for (;;) {
      // The machine's turn once the cycles have reached its next update and its clock.
      if (cycle_ns_ >= next_update_ns_ && cycle_ns_ >= clock.now_ns()) {
        if (!machine_turn()) {
          break;
        }
        continue;
      }
      if (!cycle_turn()) {
        break;
      }
    }
    job_.records().drain(job_.rings().journal, true);
    job_.machine().shut_down(clock.now_ns() + job_.parts().shut_down_bound_ns);
    outcome_.start_ns = start_ns_;
    outcome_.run_s = seconds(cycle_ns_);
    return outcome_;
  }

 private:
  [[nodiscard]] double seconds(hal::MonotonicNs at_ns) const { return static_cast<double>(at_ns - start_ns_) / 1e9; }

  // One machine update, its link's waits moving the clock; false ends the run.
  bool machine_turn() {
    hal::Clock& clock = job_.machine_clock();
    control::MachineSide& machine = job_.machine();
    clock.sleep_until_ns(cycle_ns_);
    machine.update(clock.now_ns() + kUpdateBoundUpdates * job_.parts().update_ns);
    for (JobHooks* hook : hooks_) {
      hook->after_machine_update();
    }
    control::DisplayFeed* display = job_.parts().display;
    if (display != nullptr && job_.model().ready()) {
      display->on_machine(view_of(machine), job_.model());
    }
    if (machine.state() == control::MachineSideState::Stopped && outcome_.machine_stopped_s < 0.0) {
      outcome_.machine_stopped_s = seconds(cycle_ns_);
    }
    next_update_ns_ += job_.parts().update_ns;
    // After a safe state: once the mill is stopped and the device is seen to drive no force (over a
    // wire it takes the zero command at its next millisecond), or a tenth of a second on.
    return !(stop_after_update_ && (outcome_.safe_state_s < 0.0 || outcome_.force_zero_s >= 0.0 ||
                                    seconds(cycle_ns_) - outcome_.safe_state_s > 0.1));
  }

  // One cycle at its deadline (or as late as a hook makes it); false ends the run.
  bool cycle_turn() {
    const double t_s = seconds(cycle_ns_);
    const CycleTime time{cycle_ns_, t_s};
    for (JobHooks* hook : hooks_) {
      if (!hook->before_cycle(time)) {
        return false;
      }
    }
    hal::MonotonicNs late_ns = 0;
    for (const JobHooks* hook : hooks_) {
      late_ns += hook->lateness_ns();
    }
    control::Controller& controller = job_.controller();
    const auto wall_before = std::chrono::steady_clock::now();
    const control::CycleStatus status = controller.step(cycle_ns_ + late_ns, cycle_ns_);
    outcome_.compute.add(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - wall_before).count());
    controller.finish(cycle_ns_ + late_ns, cycle_ns_ + period_ns_);
    for (JobHooks* hook : hooks_) {
      hook->after_cycle(time, status);
    }
    // The overrun watchdog may enter the safe state in finish(): it counts from this cycle.
    const bool safe = status == control::CycleStatus::SafeState || controller.safe_reason() != control::SafeReason::None;
    if (safe && outcome_.safe_state_s < 0.0) {
      outcome_.safe_state_s = t_s;
    }
    if (outcome_.safe_state_s >= 0.0 && outcome_.force_zero_s < 0.0 && options_.device_force_off &&
        options_.device_force_off()) {
      outcome_.force_zero_s = t_s;  // what the device drives: the command it took this cycle
    }
    drain_records();
    cycle_ns_ += period_ns_;
    if (safe) {
      if (!stop_after_update_) {
        stop_after_update_ = true;
        // A machine update at once: it holds and stops the mill. Unless the safe state came in
        // finish() (the overrun watchdog): this cycle's handoff went without it, and only the next
        // cycle's carries it to the machine side (and its record to the journal).
        if (status == control::CycleStatus::SafeState) {
          next_update_ns_ = std::min(next_update_ns_, cycle_ns_);
        }
      }
      return true;
    }
    keep_pace(t_s);
    return controller.statistics().cycles % 1000 != 0 || !each_second(t_s);
  }

  // The records side's work, after each cycle: the journal, the telemetry, the requests.
  void drain_records() {
    control::CycleRingStorage& rings = job_.rings();
    control::DisplayFeed* display = job_.parts().display;
    job_.records().drain(rings.journal);
    control::Telemetry frame{};
    while (rings.telemetry.pop(frame)) {
      if (display != nullptr) {
        display->on_telemetry(frame);
      }
      for (JobHooks* hook : hooks_) {
        hook->on_telemetry(frame);
      }
    }
    if (job_.controller().statistics().cycles % 20 == 0) {
      for (JobHooks* hook : hooks_) {
        hook->forward_requests(rings.commands);
      }
    }
  }

  // Paced: no further ahead of the wall clock than `pace` simulated seconds per second.
  void keep_pace(double t_s) const {
    if (options_.pace > 0.0 && job_.controller().statistics().cycles % 10 == 0) {
      std::this_thread::sleep_until(options_.wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                              std::chrono::duration<double>(t_s / options_.pace)));
    }
  }

  // Each second of the job: the journal's sync, an interrupt's stop, and whether the job is done.
  bool each_second(double t_s) {
    job_.records().sync_if_due();
    const std::atomic<bool>* interrupted = job_.parts().interrupted;
    if (interrupted != nullptr && interrupted->load()) {
      static_cast<void>(job_.rings().commands.push(
          {control::CommandKind::Stop, 0.0, control::CommandSource::Signal}));  // taken by the next cycle
    }
    const bool caught_up = job_.machine().path_left() <= 1 && job_.machine().at_goal();
    return std::any_of(hooks_.begin(), hooks_.end(), [&](JobHooks* hook) { return hook->job_done(t_s, caught_up); });
  }

  Job& job_;
  std::span<JobHooks* const> hooks_;
  const VirtualTimeRun& options_;
  const hal::MonotonicNs period_ns_;
  hal::MonotonicNs start_ns_ = 0;
  hal::MonotonicNs cycle_ns_ = 0;
  hal::MonotonicNs next_update_ns_ = 0;
  bool stop_after_update_ = false;
  RunOutcome outcome_;
};

}  // namespace

RunOutcome run_on_virtual_time(Job& job, std::span<JobHooks* const> hooks, const VirtualTimeRun& options) {
  return VirtualTimeLoop(job, hooks, options).run();
}

}  // namespace stencil::runtime
