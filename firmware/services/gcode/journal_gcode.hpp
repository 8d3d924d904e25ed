// A job's journal written as a G-code program: the path the mill was commanded (cut_path.hpp), merged
// where that stays legal, in the writer's dialect (gcode_writer.hpp). One function for every program
// that exports (stencil-journal gcode, stencil-sim --gcode).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "firmware/core/tables/part_tables.hpp"
#include "firmware/services/gcode/cut_path.hpp"
#include "firmware/services/gcode/gcode_writer.hpp"

namespace stencil::gcode {

struct JournalExport {
  CutPathSettings path;
  ProgramSettings program;        // its tool and comments are filled in here from the tables
  double merge_tolerance_mm = 0.001;
  std::string source_name;        // what the header says the program came from
  // Written in the machine's own coordinates (G53 on every move: sign x (world - home) per axis, as its
  // readout counts) instead of the part's: for a machine whose axes count against the part's, which
  // no work offset (G54) can map, or to run the cut with no touch-off.
  bool machine_coordinates = false;
  std::array<int, 3> machine_sign{1, 1, 1};
  std::uint32_t config_crc32 = 0; // the rig's configuration file these settings came from (0: compiled-in):
                                  // the journal's job must have been run with it
};

struct ExportSummary {
  std::uint64_t targets = 0;      // machine targets read
  std::uint64_t homings = 0;
  std::uint64_t legs = 0;         // feed moves before merging
  std::uint64_t moves = 0;        // moves written (feeds and traverses)
  std::uint64_t sweep_checks = 0;
  double feed_length_mm = 0.0;
};

// Reads `journal_path`, checks it was recorded on these tables (their CRC-32), and writes the program
// to `out_path` (through a temporary file beside it: a failure leaves no half program). False with
// `error` naming the file and what was wrong.
[[nodiscard]] bool export_journal_gcode(const std::string& journal_path, const tables::PartTables& part,
                                        JournalExport settings, const std::string& out_path, ExportSummary& summary,
                                        std::string& error);

// The tool of the tables as a machinist names it ("ball end mill d 3 mm, flutes 12 mm").
[[nodiscard]] std::string tool_name(const tables::PartTables& part);

}  // namespace stencil::gcode
