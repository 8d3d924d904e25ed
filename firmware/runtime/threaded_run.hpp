// A job run on threads in real time: the cycle on the periodic runner's thread each period
// (SCHED_FIFO and pinned where the program's runner makes it so), the machine side on a thread of
// its own at the update rate, and a records thread (the journal, telemetry, the display's and the
// operator's requests, the run's stop); then an ordered shutdown.
#pragma once

#include <functional>
#include <span>

#include "firmware/runtime/job.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "firmware/runtime/periodic_runner.hpp"
#include "firmware/runtime/run_outcome.hpp"

namespace stencil::runtime {

// Which safe state ends the run: any (the simulation's), or only one that follows the run's own
// stop (the rig's: a fault's safe state keeps the cycle running at zero force for a reset).
enum class SafeStateEnds : std::uint8_t { Any, AfterStop };

struct ThreadedRun {
  SafeStateEnds safe_state_ends = SafeStateEnds::Any;
  // The run's stop goes to the cycle through its command ring after this long from the first cycle
  // (0: never), as on an interrupt.
  double stop_after_s = 0.0;
  // After the cycle's last period, before the other threads stop: long enough for the machine
  // updates that take the safe state to the mill (hold, then stop).
  hal::MonotonicNs settle_ns = 0;
  // Run first on the machine thread, before its first update (its priority, below the cycle's).
  std::function<void()> prepare_machine_thread;
};

// Runs the assembled and started job until a hook says it is done or a safe state ends it (see
// SafeStateEnds); then the machine thread and the records thread stop, the last records are drained
// and the machine side stops the mill (also when the runner refused to run the cycle). Blocks.
[[nodiscard]] RunOutcome run_on_threads(Job& job, const PeriodicRunner& runner, std::span<JobHooks* const> hooks,
                                        const ThreadedRun& options);

}  // namespace stencil::runtime
