// A G-code program read through LinuxCNC's own interpreter (rs274, batch mode) into straight moves,
// each mapped back to the source line of the block that made it: what the guard follows.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace stencil::sim {

enum class GcodeMoveKind : std::uint8_t { Traverse, Feed };

struct GcodeMove {
  int line;  // 1-based source line of the block that made this move
  GcodeMoveKind kind;
  // End point, mm, in the program's own coordinates. They are the work coordinates because every
  // program that sets a non-zero G5x/G92 offset, an XY rotation or a tool length offset is refused.
  Eigen::Vector3d to_mm;
  double feed_mm_per_min;  // Feed: the programmed feed in mm/min (inch programs converted); Traverse: 0
};

struct GcodeProgram {
  // In program order; the first starts where rs274 assumes the machine to be, at 0,0,0. Arcs are
  // already sampled into Feed moves (each with the arc's line).
  std::vector<GcodeMove> moves;
  std::string tool;  // the tool the program selects before its first move (e.g. "T1"), else ""
};

struct GcodeReadOptions {
  double arc_tolerance_mm = 0.001;  // chord sag of a sampled arc at most this
  std::string rs274 = "rs274";      // the interpreter (a PATH lookup unless it holds a '/'), for tests
  double timeout_s = 30.0;          // rs274 is killed after this long (a program can loop forever)
  // rs274's canonical output may not grow past this (a program looping forever writes without end).
  std::uint64_t max_output_bytes = 512ULL << 20;
};

// Sampling stops there (a refusal naming the line): an arc of a huge radius at a tiny tolerance, or
// a block asking for millions of turns, would otherwise take all the memory.
inline constexpr std::size_t kMaxGcodeMoves = 2'000'000;

// The comment number_blocks puts at the end of every block. rs274 emits only the LAST comment of a
// line as COMMENT(...), once each time the block runs, before the block's motion: so the canon shows
// where each run of a block starts, and a block that makes several moves in one run (a canned cycle,
// G28/G30, a spline) is told apart from a one-line loop body run several times.
inline constexpr const char* kGcodeBlockMarker = "@";

// Gives every line of `source` the word N<its line number> (an existing N word is replaced, after a
// block-delete '/' if there is one) and the block marker comment as its last comment (before a ';'
// comment); '%' lines are kept as they are, a CR before the newline is dropped. rs274 prints each
// canonical call with the N word of the block that made it, and names it in its errors. The words
// added make a line about 10 characters longer: a line already near rs274's 255-character limit
// becomes its error "Command too long", named by its line. Only the marker comment of a line is
// executed (rs274 runs only the last comment): a (MSG, ...) or (DEBUG, ...) there is not shown.
// Large line numbers are fine (N1234567 tested: rs274 takes and prints them whole).
[[nodiscard]] std::string number_blocks(const std::string& source);

// Reads rs274's canonical calls (`-g` batch output) into moves. False with `error` naming the source
// line ("line 12: ...") and what was wrong for anything the guard cannot follow faithfully, any
// canonical call it does not know, or a line it cannot read ("canonical output line 7: ...").
[[nodiscard]] bool parse_canonical(const std::string& rs274_output, const GcodeReadOptions& options,
                                   GcodeProgram& program, std::string& error);

// Numbers the program's blocks, runs rs274 on it (batch mode, in a temporary folder removed
// afterwards, killed after options.timeout_s) and reads its canonical calls back. False with `error`
// naming the file, the source line and what was wrong ("part.ngc: line 12: ...").
[[nodiscard]] bool read_gcode_program(const std::string& path, const GcodeReadOptions& options,
                                      GcodeProgram& program, std::string& error);

}  // namespace stencil::sim
