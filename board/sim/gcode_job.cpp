#include "board/sim/gcode_job.hpp"

#include <algorithm>
#include <cmath>

#include "board/sim/sim_job.hpp"
#include "board/sim/sim_result.hpp"
#include "sim/mill/machined_part.hpp"

namespace stencil::board::sim {

using stencil::sim::GcodeMove;
using stencil::sim::GcodeMoveKind;

std::vector<GcodeRefusal> refused_lines(const tables::PartTables& part, const stencil::sim::GcodeProgram& program,
                                        const Eigen::Vector3d& start_mm) {
  std::vector<GcodeRefusal> refused;
  Eigen::Vector3d from = start_mm;
  for (const GcodeMove& move : program.moves) {
    const Eigen::Vector3d to = move.to_mm;
    const double length = (to - from).norm();
    if (length > 0.0) {
      // Past the start: a step in, so that a move leaving from inside the part shows less depth than
      // it started with. 0.01 mm is far above the measure's rounding and far below a move's length.
      const double step = std::min(0.01, 0.5 * length);
      const double at_start = stencil::sim::tool_depth_along(part, from, from);
      const double past_start = stencil::sim::tool_depth_along(part, from + step / length * (to - from), to);
      if (past_start > kRefusedDepthMm && past_start >= at_start - 1e-9) {
        const double depth = std::max(past_start, at_start);
        if (!refused.empty() && refused.back().line == move.line) {
          refused.back().depth_mm = std::max(refused.back().depth_mm, depth);  // an arc's chords: one line
        } else {
          refused.push_back({move.line, depth});
        }
      }
    }
    from = to;
  }
  return refused;
}

stencil::sim::OperatorScript gcode_script(const stencil::sim::GcodeProgram& program, const Eigen::Vector3d& start_mm,
                                          double top_speed_mm_per_s, double device_mm_per_world_mm) {
  stencil::sim::OperatorScript script;
  stencil::sim::walk_to(script, start_mm, top_speed_mm_per_s, device_mm_per_world_mm);
  Eigen::Vector3d at = start_mm;
  for (const GcodeMove& move : program.moves) {
    if (move.to_mm == at) {
      continue;
    }
    const double speed = move.kind == GcodeMoveKind::Traverse
                             ? top_speed_mm_per_s
                             : std::min(top_speed_mm_per_s, move.feed_mm_per_min / 60.0);
    stencil::sim::walk_to(script, move.to_mm, speed, device_mm_per_world_mm);
    at = move.to_mm;
  }
  return script;
}

void cut_directly(const tables::PartTables& part, const stencil::sim::StockBox& stock, const motion::MachineFrames& frames,
                  const stencil::sim::GcodeProgram& program, const Eigen::Vector3d& start_mm, SimResult& result) {
  stencil::sim::MachinedPart machined(part, stock, frames, [] { return 0.0; });
  Eigen::Vector3d from = start_mm;
  for (const GcodeMove& move : program.moves) {
    machined.cut_recorded_leg(from, move.to_mm);
    from = move.to_mm;
  }
  result.started = true;
  result.machine_updates = program.moves.size();
  fill_machined(result, machined);
}

}  // namespace stencil::board::sim
