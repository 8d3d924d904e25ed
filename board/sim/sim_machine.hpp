// SimMachine: the simulation's machine as the job sees it, whichever it is: the fake CY545 on a pty
// driving the simulated mill (MillWiring), or the real LinuxCNC driving its own simulated mill
// (LinuxcncWiring). The driver's end of the link, the clock it paces on, the ground truth of what was
// machined, and what a machinist finds at the mill once the job is over.
#pragma once

#include <string>

#include "board/sim/sim_job.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "hal/clock.hpp"
#include "hal/machine_link.hpp"
#include "sim/mill/machined_part.hpp"

namespace stencil::board::sim {

class SimMachine : public runtime::JobHooks {
 public:
  // Empty when the link can be started; else why not.
  [[nodiscard]] virtual const std::string& error() const = 0;
  [[nodiscard]] virtual hal::MachineLink& link() = 0;
  // The link's last error, for the report (LinuxCNC's own words, the CY545's bytes).
  [[nodiscard]] virtual const char* link_error() const = 0;
  [[nodiscard]] virtual hal::Clock& clock() = 0;
  [[nodiscard]] virtual stencil::sim::MachinedPart& machined() = 0;
  [[nodiscard]] virtual const stencil::sim::MachinedPart& machined() const = 0;
  // Real time: the far side answers from now (a thread of the fake's own), until stop_answering().
  virtual void start_answering() {}
  virtual void stop_answering() {}
  // Once homed: the machined part counts from where the mill is now.
  virtual void arm() = 0;
  // At the end, once the machine side has stopped the mill (at now_ns): what is left on, and the
  // ground truth brought up to date.
  virtual void leave(SimResult& result, bool stop_confirmed, hal::MonotonicNs now_ns) = 0;

 protected:
  ~SimMachine() = default;
};

}  // namespace stencil::board::sim
