// A job's report, written the same way whichever board ran it: the figures every job has (the
// cycle's timing, the force, the machine, the controller's model of the stock, the safe state, the
// whole job over every run its journal holds), and the sections only one board can measure (the
// simulation's ground truth of what was cut; the rig's faults and resets), each added by its board.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "firmware/core/control/loop_statistics.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/journal/job_history.hpp"

namespace stencil::report {

struct Quantiles {
  double p50, p99, p999, max;
};

// p50, p99, p99.9 and the most of a histogram, in microseconds.
[[nodiscard]] Quantiles quantiles_of(const control::MicrosecondHistogram& histogram);

struct JobFigures {
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  std::uint64_t missed_periods = 0;
  Quantiles wakeup_latency_us{};  // on virtual time: 0
  Quantiles compute_us{};         // wall clock: the cycle's own work
  double max_force_n = 0.0;       // over the whole job
  double max_offset_mm = 0.0;
  std::uint64_t machine_updates = 0;
  double machine_max_lag_mm = 0.0;
  bool machine_stop_confirmed = false;  // the link confirmed spindle and drivers off at the end
  std::string machine_error;            // the link's last error, when it faulted
  double model_removed_volume_mm3 = 0.0;  // the controller's model of the stock it commanded
  control::SafeReason safe_state = control::SafeReason::None;
  // The job before this run, from the journal it resumed (earlier.segments 0: a fresh job), and the
  // touched set rebuilt from it.
  journal::JobHistory earlier;
  std::uint32_t touched_rebuilt = 0;
};

// The report: the figures as JSON, with `board_sections` merged in (an object; its keys add to the
// figures' at any depth, {"machine": {"take_ups": 3}} adds a key to the machine's section, and a
// null is written as null).
// False with `error` naming the path when it cannot be written.
[[nodiscard]] bool write_job_report(const std::string& path, const JobFigures& figures,
                                    const nlohmann::json& board_sections, std::string& error);

}  // namespace stencil::report
