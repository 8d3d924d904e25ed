// A G-code program in the simulation (issue 28): as the operator's motion under the stencil (the
// guard: what the program would have done to the part, line by line), and cut by the simulated mill
// directly, with no stencil (what the program does when run on a mill as it is).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "board/sim/sim_job.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "sim/gcode/gcode_program.hpp"
#include "sim/mill/stock_zmap.hpp"
#include "sim/operator/operator_script.hpp"

namespace stencil::board::sim {

// Deeper than this into the part is a move the stencil refuses (well under the surface tolerance's
// effect on the cut, well over the rounding of 5-decimal G-code).
inline constexpr double kRefusedDepthMm = 0.001;

// The lines whose moves (from `start_mm`, the tool's tip after homing) would go into the part,
// in order, each once with its deepest. A move counts when, past its start, it goes at least as deep
// as it started and deeper than kRefusedDepthMm: one that only leaves the part (the retract after a
// refused plunge) is not the stencil's doing and is not listed.
[[nodiscard]] std::vector<GcodeRefusal> refused_lines(const tables::PartTables& part, const stencil::sim::GcodeProgram& program,
                                                      const Eigen::Vector3d& start_mm);

// The operator's script that follows the program from `start_mm`: each move at its feed (traverses
// at the top speed), never faster than `top_speed_mm_per_s` (the hand keeps to what the mill can
// follow, so the virtual tool follows the program's path, not a shortcut of it).
[[nodiscard]] stencil::sim::OperatorScript gcode_script(const stencil::sim::GcodeProgram& program, const Eigen::Vector3d& start_mm,
                                                        double top_speed_mm_per_s, double device_mm_per_world_mm);

// The program's moves cut straight into the stock by the simulated mill's tool (no stencil, no
// controller), from `start_mm`: the removed stock, the gouge, the picture's heights in `result`.
void cut_directly(const tables::PartTables& part, const stencil::sim::StockBox& stock, const motion::MachineFrames& frames,
                  const stencil::sim::GcodeProgram& program, const Eigen::Vector3d& start_mm, SimResult& result);

}  // namespace stencil::board::sim
