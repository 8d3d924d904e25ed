// A job's report, written the same way whichever board ran it: the figures every job has (the
// cycle's timing, the force, the machine, the controller's model of the stock, the safe state, the
// whole job over every run its journal holds), and the sections only one board can measure (the
// simulation's ground truth of what was cut; the rig's faults and resets), each added by its board.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/loop_statistics.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/report/provenance.hpp"

namespace stencil::report {

struct Quantiles {
  double p50, p99, p999, max;
};

// p50, p99, p99.9 and the most of a histogram, in microseconds.
[[nodiscard]] Quantiles quantiles_of(const control::MicrosecondHistogram& histogram);

// The operator's parameters as they stood (the same units as the commands that set them).
struct OperatorLimits {
  double coupling_n_per_device_mm = 0.0;
  double force_limit_n = 0.0;
  double speed_limit_mm_per_s = 0.0;  // infinity: unlimited
  // The wall's feel (engine::WallFeel): N s per device metre, 0 to 1, and the speed-limiting mode.
  double damping_n_s_per_m = 0.0;
  double friction = 0.0;
  engine::SpeedLimiting speed_limiting = engine::SpeedLimiting::Cap;
};

// Where everything stood when the run ended: a machine's position readout, in millimetres.
struct FinalPositions {
  double device_mm[3] = {0, 0, 0};           // the device's tip, device space
  double virtual_work_mm[3] = {0, 0, 0};     // the virtual tool's tip, the part's (work) coordinates
  double virtual_machine_mm[3] = {0, 0, 0};  // the same in machine coordinates (from home)
  double mill_work_mm[3] = {0, 0, 0};        // the last target sent to the mill, work coordinates
  double mill_machine_mm[3] = {0, 0, 0};     // the same in machine coordinates
};

// What the operator did and what came of it: every command the cycle took, in order, the limits
// in force at the start, the feed holds, where a safe state came from and where everything ended.
struct OperatorRecord {
  std::vector<control::CommandEvent> commands;  // the first journal::JournalDrain::kMaxListed
  std::uint64_t commands_unlisted = 0;
  OperatorLimits initial_limits;
  std::int64_t start_ns = 0;  // the run's first cycle's deadline: a command's time counts from here
  double period_s = 1e-3;
  std::uint64_t machine_holds = 0;       // feed holds the machine side took to the link
  std::uint64_t machine_held_updates = 0;
  control::CommandSource safe_source = control::CommandSource::Cycle;
  FinalPositions positions;
};

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
  OperatorRecord operator_record;
  Provenance provenance;  // what made it: the report's "provenance" section
};

// The report: the figures as JSON, with `board_sections` merged in (an object; its keys add to the
// figures' at any depth, {"machine": {"take_ups": 3}} adds a key to the machine's section, and a
// null is written as null).
// False with `error` naming the path when it cannot be written.
[[nodiscard]] bool write_job_report(const std::string& path, const JobFigures& figures,
                                    const nlohmann::json& board_sections, std::string& error);

}  // namespace stencil::report
