// RunOutcome: what a job's run says of itself once it has stopped, beside what its parts say (the
// controller's and the machine side's statistics, the model of the stock), which the boards read
// from the job.
#pragma once

#include <string>

#include "firmware/core/control/loop_statistics.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "hal/clock.hpp"

namespace stencil::runtime {

struct RunOutcome {
  bool ran = true;    // false: the periodic runner refused to run the cycle (error says why)
  std::string error;
  hal::MonotonicNs start_ns = 0;  // the first cycle's deadline (0: no cycle ran)
  // From the first cycle's deadline to the end: in real time, wall time to the machine's stop; in
  // virtual time, the cycles' time.
  double run_s = 0.0;
  // How long the cycle's steps took, wall clock: in real time the controller's own statistics; in
  // virtual time the run's (the controller's would count the virtual clock).
  control::MicrosecondHistogram compute;
  control::SafeReason first_fault = control::SafeReason::None;  // the first safe state not asked for (real time)
  // Virtual time, seconds from the first cycle (negative: never happened): the first cycle in the
  // safe state; from then, the first cycle the device drove no force; the update that stopped the mill.
  double safe_state_s = -1.0;
  double force_zero_s = -1.0;
  double machine_stopped_s = -1.0;
};

}  // namespace stencil::runtime
