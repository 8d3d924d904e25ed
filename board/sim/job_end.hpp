// JobEnd: when a simulated job has done its work, checked each second of it: once every reachable
// triangle is touched and the mill has caught up (until_complete), or once the script is over and the
// mill has caught up with the virtual tool or been given long enough to. And the progress line. A
// hook of the job's run.
#pragma once

#include "board/sim/sim_job.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/runtime/job_hooks.hpp"

namespace stencil::board::sim {

class JobEnd final : public runtime::JobHooks {
 public:
  // `job` and `controller` must outlive the hook.
  JobEnd(const SimJob& job, const control::Controller& controller);

  bool job_done(double t_s, bool machine_caught_up) override;

  [[nodiscard]] bool complete() const { return complete_; }  // until_complete met

 private:
  const SimJob& job_;
  const control::Controller& controller_;
  double duration_s_;
  double next_progress_s_ = 10.0;
  bool complete_ = false;
};

}  // namespace stencil::board::sim
