// JobHooks: what a board adds to a job's run, at the points the runtime defines, without a branch of
// its own in the runtime's loops: the simulated operator and its mill, an injected fault, a replayed
// journal, the rig's lines to the operator. Each method's default adds nothing; a run calls its
// hooks in the order it was given them, at each point.
#pragma once

#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "hal/clock.hpp"

namespace stencil::runtime {

// When a cycle runs: its start (in virtual time, its deadline) and how long after the job's first
// cycle's deadline, seconds.
struct CycleTime {
  hal::MonotonicNs now_ns;
  double t_s;
};

class JobHooks {
 public:
  JobHooks() = default;
  JobHooks(const JobHooks&) = delete;
  JobHooks& operator=(const JobHooks&) = delete;

  // The cycle's thread, before each cycle (in virtual time, in the cycle's place among the machine
  // updates). False ends the run before this cycle (a replay out of records); the hooks after this
  // one are not called then.
  virtual bool before_cycle(const CycleTime& /*time*/) { return true; }

  // Virtual time only: how late this cycle starts after its deadline (an injected stalled host).
  [[nodiscard]] virtual hal::MonotonicNs lateness_ns() const { return 0; }

  // The cycle's thread, after each cycle's step() and finish().
  virtual void after_cycle(const CycleTime& /*time*/, control::CycleStatus /*status*/) {}

  // Every 1000th cycle (each second of the job) that ended outside the safe state: true when the job
  // has done its work, which ends the run. `machine_caught_up`: the mill is at the virtual tool.
  virtual bool job_done(double /*t_s*/, bool /*machine_caught_up*/) { return false; }

  // The machine side's thread (in virtual time, its turn), after each update.
  virtual void after_machine_update() {}

  // Where the records are drained (the records thread; in virtual time, after each cycle): each
  // telemetry frame the cycle published.
  virtual void on_telemetry(const control::Telemetry& /*frame*/) {}

  // Where operator requests go into the command ring, whose one producer calls this (the records
  // thread until the run's stop is sent; in virtual time, with the display's requests).
  virtual void forward_requests(control::CommandRing& /*commands*/) {}

  // Real time only: after each pass of the records thread (about 20 times a second).
  virtual void after_records_pass() {}

 protected:
  ~JobHooks() = default;
};

}  // namespace stencil::runtime
