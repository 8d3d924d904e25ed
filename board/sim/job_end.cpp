// The end of a simulated job.
#include "board/sim/job_end.hpp"

#include <limits>

#include "board/sim/sim_result.hpp"

namespace stencil::board::sim {
namespace {

// After the script, the mill is given up to this long to catch up with the virtual tool.
constexpr double kCatchUpS = 30.0;

}  // namespace

JobEnd::JobEnd(const SimJob& job, const control::Controller& controller)
    : job_(job),
      controller_(controller),
      // A replay ends with its records.
      duration_s_(job.replay != nullptr ? std::numeric_limits<double>::infinity()
                  : job.duration_s > 0.0 ? job.duration_s
                                         : job.script.duration_s()) {}

bool JobEnd::job_done(double t_s, bool machine_caught_up) {
  const double coverage = reachable_coverage(*job_.part, controller_.touched());
  if (job_.progress && t_s >= next_progress_s_) {
    job_.progress(t_s, coverage);
    next_progress_s_ += 10.0;
  }
  if (job_.until_complete && coverage >= 1.0 && machine_caught_up) {
    complete_ = true;
    return true;
  }
  return t_s >= duration_s_ && (machine_caught_up || t_s >= duration_s_ + kCatchUpS);
}

}  // namespace stencil::board::sim
