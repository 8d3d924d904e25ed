// A job so far, from its journal: what a resume needs to carry on (the touched set and the stock as
// machined, rebuilt record by record) and what its report needs to cover the whole job.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "firmware/core/motion/machine_frames.hpp"

namespace stencil::journal {

struct RecordedFault {
  std::uint32_t segment;  // 0: the first run, 1 the first resume, ...
  std::uint64_t cycle;    // in that segment
  control::SafeReason reason;
};

// How a run ended: in order (its End record: finished, or in a safe state), or unrecorded (killed,
// crashed, the power gone).
struct RunEnding {
  bool recorded;
  control::SafeReason reason;  // when recorded
  std::uint64_t cycles;        // cycle records the run left
};

struct JobHistory {
  JournalStart start;
  std::uint32_t segments = 0;           // runs recorded: 1 + the resumes
  std::uint64_t cycles = 0;             // cycle records, all segments
  double recorded_s = 0.0;              // the segments' cycles' time spans, added up
  std::uint64_t homings = 0;
  std::uint64_t machine_commands = 0;
  std::uint64_t machined_legs = 0;      // single-axis legs they make
  std::vector<RecordedFault> faults;    // every safe-state event, in order
  std::vector<RunEnding> endings;       // one per run
  std::uint32_t touched_recorded = 0;   // the touched set's size at the last cycle recorded
  double max_force_n = 0.0;
  double max_offset_mm = 0.0;           // device against virtual tool, world
  // The last virtual tool recorded whole (version 5 keeps it at keys, a second apart, and where the
  // touched set grew; so it may be up to a second older than the last cycle).
  bool has_cycle = false;
  Eigen::Vector3d last_virtual_tip_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_commanded_tip_mm = Eigen::Vector3d::Zero();  // home until the first target
  double script_s = 0.0;                // a simulated operator's script had got this far
  std::vector<std::size_t> run_starts;  // where each run after the first starts (its Resume record)
  std::size_t good_bytes = 0;           // whole records end here: a resume cuts the file to this
  std::string tail;                     // what the torn tail was, when there was one
};

// What to rebuild while reading (either may be empty): each recorded virtual tool tip that differs
// from the one before it, in order; each single-axis leg the recorded targets sent the tool along
// (from home after each homing), world mm.
struct HistoryRebuild {
  std::function<void(const Eigen::Vector3d& tip_mm)> virtual_tip;
  std::function<void(const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm)> machined_leg;
};

// Reads `path` (its first `limit_bytes` at most: what it held before this run carried it on). False with `error` naming the file and what is wrong (unreadable, damaged, no start
// record, recorded with other tables than `tables_crc32` / `triangle_count`).
[[nodiscard]] bool read_job_history(const std::string& path, std::uint32_t tables_crc32, std::uint32_t triangle_count,
                                    const motion::MachineFrames& frames, const HistoryRebuild& rebuild,
                                    JobHistory& history, std::string& error,
                                    std::size_t limit_bytes = std::numeric_limits<std::size_t>::max());

}  // namespace stencil::journal
