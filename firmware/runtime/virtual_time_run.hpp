// A job run in virtual time on one thread (stencil-sim --fast): the cycle runs period after period
// until its time reaches the machine's; then the machine side runs one update, whose link waits move
// the machine's clock (the board's: in the simulation the fake CY545's, which runs the fake and the
// mill as long as the serial line and the moves take). The machine only ever sees the handoffs of
// cycles before its update, as on the rig, and nothing depends on the wall clock: the same job gives
// the same records.
#pragma once

#include <chrono>
#include <functional>
#include <span>

#include "firmware/runtime/job.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "firmware/runtime/run_outcome.hpp"

namespace stencil::runtime {

struct VirtualTimeRun {
  // At most this many simulated seconds per wall-clock second from wall_start (0: as fast as it
  // goes), so a person can watch a deterministic run.
  double pace = 0.0;
  std::chrono::steady_clock::time_point wall_start{};
  // Whether the device drives no force now (what it drives, not the command it was given): from a
  // safe state on, the first cycle after which it drives none is the outcome's force_zero_s.
  std::function<bool()> device_force_off;
};

// Runs the assembled and started job until a hook ends it (out of records, or done), or a safe state:
// then until the mill is stopped and the device drives no force, or a tenth of a second on. Then the
// last records are drained and the machine side stops the mill. Blocks.
[[nodiscard]] RunOutcome run_on_virtual_time(Job& job, std::span<JobHooks* const> hooks, const VirtualTimeRun& options);

}  // namespace stencil::runtime
