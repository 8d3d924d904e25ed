// A job on threads: the cycle, the machine thread and the records thread, and how they stop.
#include "firmware/runtime/threaded_run.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "hal/posix_clock/monotonic_clock.hpp"

namespace stencil::runtime {
namespace {

// What the three threads share while the job runs, and each one's loop.
class JobThreads {
 public:
  JobThreads(Job& job, std::span<JobHooks* const> hooks, const ThreadedRun& options)
      : job_(job), hooks_(hooks), options_(options) {}

  // The machine side at the update rate, paced on the link's clock, each update bounded from its
  // actual start (an update that outlasts its period makes the mill fall behind, never a fault).
  void machine_loop() {
    if (options_.prepare_machine_thread) {
      options_.prepare_machine_thread();  // its priority: below the cycle, above the records thread
    }
    const JobParts& parts = job_.parts();
    hal::Clock& clock = job_.machine_clock();
    control::MachineSide& machine = job_.machine();
    hal::MonotonicNs next = clock.now_ns();
    while (!stop.load()) {
      clock.sleep_until_ns(next);
      machine.update(std::max(next, clock.now_ns()) + kUpdateBoundUpdates * parts.update_ns);
      for (JobHooks* hook : hooks_) {
        hook->after_machine_update();
      }
      if (parts.display != nullptr && job_.model().ready()) {
        parts.display->on_machine(view_of(machine), job_.model());
      }
      caught_up_.store(machine.path_left() <= 1 && machine.at_goal());
      next = std::max(next + parts.update_ns, clock.now_ns());
    }
  }

  // The journal (every record the cycle left, every target the machine thread queued), the
  // telemetry, the requests into the command ring (whose one producer this thread is) and the
  // run's stop.
  void records_loop() {
    journal::JournalDrain& records = job_.records();
    control::CycleRingStorage& rings = job_.rings();
    control::DisplayFeed* display = job_.parts().display;
    bool stop_sent = false;
    while (!stop.load()) {
      records.drain(rings.journal);
      records.sync_if_due();
      control::Telemetry frame{};
      while (rings.telemetry.pop(frame)) {
        if (display != nullptr) {
          display->on_telemetry(frame);
        }
        for (JobHooks* hook : hooks_) {
          hook->on_telemetry(frame);
        }
      }
      // After the stop, nothing more: it is the last command the cycle takes.
      if (!stop_sent) {
        for (JobHooks* hook : hooks_) {
          hook->forward_requests(rings.commands);
        }
        stop_sent = send_stop_when_asked();
      }
      for (JobHooks* hook : hooks_) {
        hook->after_records_pass();
      }
      // Or less: a target the machine thread queued wakes this thread, which writes it at once, so
      // the machine side sends it at its next update.
      records.wait(std::chrono::milliseconds(50));
    }
  }

  // One cycle on the runner's thread; false ends the run.
  bool cycle(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns) {
    if (start_ns.load(std::memory_order_relaxed) == 0) {
      start_ns.store(deadline_ns);
    }
    const CycleTime time{now_ns, static_cast<double>(now_ns - start_ns.load(std::memory_order_relaxed)) / 1e9};
    for (JobHooks* hook : hooks_) {
      if (!hook->before_cycle(time)) {
        return false;
      }
    }
    control::Controller& controller = job_.controller();
    const control::CycleStatus status = controller.step(now_ns, deadline_ns);
    controller.finish(hal::posix_clock::monotonic_now_ns(), deadline_ns + job_.parts().period_ns);
    const control::SafeReason reason = controller.safe_reason();
    if (reason != control::SafeReason::None && reason != control::SafeReason::Stopped &&
        first_fault.load(std::memory_order_relaxed) == control::SafeReason::None) {
      first_fault.store(reason, std::memory_order_relaxed);
    }
    for (JobHooks* hook : hooks_) {
      hook->after_cycle(time, status);
    }
    // A stop in a fault's safe state keeps the fault as the latched reason: the run ends on the stop
    // having been asked, once the cycle is safe.
    if (status == control::CycleStatus::SafeState &&
        (options_.safe_state_ends == SafeStateEnds::Any || stop_asked_.load(std::memory_order_acquire))) {
      return false;
    }
    if (controller.statistics().cycles % 1000 != 0) {
      return true;
    }
    const bool caught_up = caught_up_.load();
    return std::none_of(hooks_.begin(), hooks_.end(), [&](JobHooks* hook) { return hook->job_done(time.t_s, caught_up); });
  }

  std::atomic<bool> stop{false};
  std::atomic<hal::MonotonicNs> start_ns{0};
  std::atomic<control::SafeReason> first_fault{control::SafeReason::None};

 private:
  // The run ends through the cycle's own stop, on an interrupt or when its time is up: true once the
  // command ring took it (a full ring is tried again at the next pass).
  bool send_stop_when_asked() {
    const hal::MonotonicNs started = start_ns.load();
    const bool time_up = options_.stop_after_s > 0.0 && started != 0 &&
                         static_cast<double>(job_.machine_clock().now_ns() - started) / 1e9 >= options_.stop_after_s;
    const std::atomic<bool>* interrupted = job_.parts().interrupted;
    if ((interrupted == nullptr || !interrupted->load()) && !time_up) {
      return false;
    }
    stop_asked_.store(true, std::memory_order_release);
    const bool by_signal = interrupted != nullptr && interrupted->load();
    return job_.rings().commands.push(
        {control::CommandKind::Stop, 0.0, by_signal ? control::CommandSource::Signal : control::CommandSource::Program});
  }

  Job& job_;
  std::span<JobHooks* const> hooks_;
  const ThreadedRun& options_;
  std::atomic<bool> caught_up_{false};
  std::atomic<bool> stop_asked_{false};
};

}  // namespace

RunOutcome run_on_threads(Job& job, const PeriodicRunner& runner, std::span<JobHooks* const> hooks,
                          const ThreadedRun& options) {
  JobThreads threads(job, hooks, options);
  std::thread machine_thread([&threads] { threads.machine_loop(); });
  std::thread records_thread([&threads] { threads.records_loop(); });
  RunOutcome outcome;
  std::string refused;
  outcome.ran = runner(
      job.parts().period_ns, threads.stop,
      [&threads](hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns) { return threads.cycle(now_ns, deadline_ns); },
      refused);
  // The machine updates that take a safe state to the mill (hold, then stop), then everything stops.
  std::this_thread::sleep_for(std::chrono::nanoseconds(options.settle_ns));
  threads.stop.store(true);
  machine_thread.join();
  records_thread.join();
  job.records().drain(job.rings().journal, true);  // the last records, left after the records thread's last look
  // And the last telemetry, so a display ends on the cycle's last state.
  for (control::Telemetry frame{}; job.rings().telemetry.pop(frame);) {
    if (job.parts().display != nullptr) {
      job.parts().display->on_telemetry(frame);
    }
  }
  // Also when the runner refused before the cycle ran (or the cycle never reached the machine side):
  // the machine is stopped here all the same, while its far end still answers.
  job.machine().shut_down(job.machine_clock().now_ns() + job.parts().shut_down_bound_ns);
  if (!outcome.ran) {
    outcome.error = refused;
  }
  outcome.start_ns = threads.start_ns.load();
  outcome.run_s = outcome.start_ns != 0
                      ? static_cast<double>(job.machine_clock().now_ns() - outcome.start_ns) / 1e9
                      : 0.0;
  outcome.compute = job.controller().statistics().compute;
  outcome.first_fault = threads.first_fault.load();
  return outcome;
}

}  // namespace stencil::runtime
