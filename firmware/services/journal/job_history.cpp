// The job so far: one pass over its journal.
#include "firmware/services/journal/job_history.hpp"

#include <algorithm>
#include <cstdio>

#include "firmware/services/journal/journal_reader.hpp"

namespace stencil::journal {

bool read_job_history(const std::string& path, std::uint32_t tables_crc32, std::uint32_t triangle_count,
                      const motion::MachineFrames& frames, const HistoryRebuild& rebuild, JobHistory& history,
                      std::string& error, std::size_t limit_bytes) {
  history = JobHistory{};
  history.last_commanded_tip_mm = frames.home_world_mm;
  bool started = false;
  bool misplaced = false;  // a record before the start record
  // The segment being read: its first and last cycle's time, and where its script started.
  std::int64_t first_ns = 0, last_ns = 0;
  bool segment_has_cycle = false;
  double segment_script_s = 0.0, segment_approach_s = 0.0;
  std::uint64_t segment_cycles = 0;
  RunEnding ending{false, control::SafeReason::None, 0};
  const auto close_segment = [&] {
    ending.cycles = segment_cycles;
    history.endings.push_back(ending);
    ending = {false, control::SafeReason::None, 0};
    segment_cycles = 0;
    if (segment_has_cycle) {
      const double span_s = static_cast<double>(last_ns - first_ns) / 1e9 + 1e-3;  // the last cycle's period too
      history.recorded_s += span_s;
      history.script_s = segment_script_s + std::max(0.0, span_s - segment_approach_s);
    } else {
      history.script_s = segment_script_s;
    }
    segment_has_cycle = false;
  };
  JournalVisitor visit;
  std::size_t record_offset = 0;
  visit.offset = [&](std::size_t offset) { record_offset = offset; };
  visit.start = [&](const JournalStart& start) {
    misplaced = misplaced || started;
    started = true;
    history.start = start;
    history.segments = 1;
  };
  visit.cycle = [&](const RecordedCycle& recorded) {
    const control::JournalRecord& r = recorded.record;
    misplaced = misplaced || !started;
    ++history.cycles;
    ++segment_cycles;
    history.touched_recorded = r.touched_triangles;
    if (!segment_has_cycle) {
      first_ns = r.time_ns;
      segment_has_cycle = true;
    }
    last_ns = r.time_ns;
    if (recorded.maxima_recorded) {
      history.max_force_n = std::max(history.max_force_n, r.max_force_n);
      history.max_offset_mm = std::max(history.max_offset_mm, r.max_offset_mm);
    }
    // A compact cycle without its tool touched nothing new (the writer keeps the tool of every cycle
    // whose touched set grew), so the tips recorded rebuild the whole set.
    if (!recorded.tool_recorded) {
      return;
    }
    const Eigen::Vector3d tip(r.virtual_tip_mm[0], r.virtual_tip_mm[1], r.virtual_tip_mm[2]);
    if (rebuild.virtual_tip && (!history.has_cycle || tip != history.last_virtual_tip_mm)) {
      rebuild.virtual_tip(tip);
    }
    history.has_cycle = true;
    history.last_virtual_tip_mm = tip;
    if (recorded.maxima_recorded) {
      return;
    }
    const double force = Eigen::Vector3d(r.force_n[0], r.force_n[1], r.force_n[2]).norm();
    history.max_force_n = std::max(history.max_force_n, force);
    if (r.safe_reason == control::SafeReason::None) {
      const Eigen::Vector3d desired =
          motion::device_to_world(frames, Eigen::Vector3d(r.device_mm[0], r.device_mm[1], r.device_mm[2]));
      if (desired.allFinite()) {
        history.max_offset_mm = std::max(history.max_offset_mm, (desired - tip).norm());
      }
    }
  };
  visit.safe_state = [&](std::uint64_t cycle, control::SafeReason reason) {
    misplaced = misplaced || !started;
    history.faults.push_back({history.segments - 1, cycle, reason});
  };
  visit.homed = [&](std::int64_t) {
    misplaced = misplaced || !started;
    ++history.homings;
    history.last_commanded_tip_mm = frames.home_world_mm;
  };
  visit.machine_command = [&](const control::MachineCommandRecord& c) {
    misplaced = misplaced || !started;
    ++history.machine_commands;
    // The legs as the machine side sent them: one axis at a time in the recorded order.
    Eigen::Vector3d at = history.last_commanded_tip_mm;
    for (const std::uint8_t axis : c.order) {
      if (axis > 2) {
        continue;
      }
      Eigen::Vector3d next = at;
      next[axis] = c.target_tip_mm[axis];
      if (next != at) {
        ++history.machined_legs;
        if (rebuild.machined_leg) {
          rebuild.machined_leg(at, next);
        }
      }
      at = next;
    }
    history.last_commanded_tip_mm = Eigen::Vector3d(c.target_tip_mm[0], c.target_tip_mm[1], c.target_tip_mm[2]);
  };
  visit.end = [&](std::uint64_t, control::SafeReason reason) {
    misplaced = misplaced || !started;
    ending.recorded = true;
    ending.reason = reason;
  };
  visit.resume = [&](const JournalResume& resume) {
    misplaced = misplaced || !started;
    close_segment();
    history.run_starts.push_back(record_offset);
    ++history.segments;
    segment_script_s = resume.script_s;
    segment_approach_s = resume.approach_s;
  };
  const JournalReadResult read = read_journal_file(path, visit, limit_bytes);
  if (!read.ok) {
    error = read.error;
    return false;
  }
  close_segment();
  if (!started || misplaced) {
    error = path + ": " + (started ? "a record before the start record, or a second start record"
                                   : "no start record (expected one first, naming the tables)");
    return false;
  }
  if (history.start.tables_crc32 != tables_crc32 || history.start.triangle_count != triangle_count) {
    char text[200];
    std::snprintf(text, sizeof text,
                  ": recorded with the tables of CRC-32 %08x and %u triangles; these are %08x with %u triangles",
                  history.start.tables_crc32, history.start.triangle_count, tables_crc32, triangle_count);
    error = path + text;
    return false;
  }
  history.good_bytes = read.good_bytes;
  history.tail = read.tail;
  return true;
}

}  // namespace stencil::journal
