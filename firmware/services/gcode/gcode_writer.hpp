// A cut as a G-code program any CNC can run: millimetres, absolute, work coordinates (the part's
// own: G54 set so that the part's origin is X0 Y0 Z0), exact path (G61), so that the controller
// that runs it moves the path that was checked, not a blend of it.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "firmware/services/gcode/cut_path.hpp"

namespace stencil::gcode {

struct ProgramSettings {
  std::vector<std::string> comments;  // the header's lines of explanation (no parentheses in them)
  std::string tool;                   // the tool, as a machinist names it (a comment beside T1 M6)
  double spindle_rpm = 2800.0;
  double safe_z_mm = 25.0;            // the retract's height, work coordinates: above anything
  double min_feed_mm_per_min = 1.0;   // a slower recorded move is written at this
  std::string motion_prefix;          // "G53 " on every motion: the machine's own coordinates
};

// Writes the program. A feed is each move's recorded length over its time, in mm/min, written when
// it changes by more than 1 %; coordinates with 5 decimals (the mill's steps are 1/640 mm: 0.0016);
// only the axes that change. The last move is a retract to the safe height (the top of the travel).
[[nodiscard]] bool write_program(std::FILE* out, const std::vector<CutMove>& moves, const Eigen::Vector3d& start_mm,
                                 const ProgramSettings& settings);

}  // namespace stencil::gcode
