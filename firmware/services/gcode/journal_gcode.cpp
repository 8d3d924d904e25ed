#include "firmware/services/gcode/journal_gcode.hpp"

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "firmware/core/geometry/tool_spec.hpp"
#include "firmware/services/journal/journal_reader.hpp"

namespace stencil::gcode {

std::string tool_name(const tables::PartTables& part) {
  const tables::TableHeader& h = part.header;
  const char* kind = h.tool_kind == static_cast<std::uint32_t>(geometry::CutterKind::Ball)       ? "ball end mill"
                     : h.tool_kind == static_cast<std::uint32_t>(geometry::CutterKind::BullNose) ? "bull-nose end mill"
                                                                                                 : "flat end mill";
  char text[160];
  std::snprintf(text, sizeof text, "%s d %.3f mm, flutes %.3f mm", kind, h.tool_diameter_mm, h.tool_flute_length_mm);
  return text;
}

bool export_journal_gcode(const std::string& journal_path, const tables::PartTables& part, JournalExport settings,
                          const std::string& out_path, ExportSummary& summary, std::string& error) {
  std::optional<CutPath> path;
  bool tables_match = true;
  std::uint32_t job_config_crc32 = 0;
  bool started = false;
  std::string command_error;
  journal::JournalVisitor visit;
  visit.start = [&](const journal::JournalStart& start) {
    started = true;
    tables_match = tables_match && start.tables_crc32 == part.header.crc32;
    // The programs note a configured rig in the job's text; the compiled-in rig's text has no such word.
    const std::size_t at = start.job.find("config-crc32=");
    if (at != std::string::npos) {
      job_config_crc32 = static_cast<std::uint32_t>(std::strtoul(start.job.c_str() + at + 13, nullptr, 16));
    }
    // stencil-rig records the job's touch-off (its work offset and the tool's stick-out): the tool's
    // tip at home is there, whatever the configuration's default.
    double x = 0.0, y = 0.0, z = 0.0, stick_out = 0.0, reference = 0.0;
    const std::size_t offset = start.job.find("work-offset=");
    if (!path && offset != std::string::npos &&
        std::sscanf(start.job.c_str() + offset, "work-offset=%lf,%lf,%lf tool-stick-out=%lf reference-stick-out=%lf", &x, &y,
                    &z, &stick_out, &reference) == 5) {
      settings.path.home_world_mm = {x, y, z - (stick_out - reference)};
      settings.program.safe_z_mm = settings.path.home_world_mm.z();
    }
    if (!path) {
      path.emplace(settings.path);
    }
  };
  visit.homed = [&](std::int64_t) {
    if (!path) {
      return;  // before any start: the reader refuses such a journal
    }
    path->homed();
    ++summary.homings;
  };
  visit.machine_command = [&](const control::MachineCommandRecord& record) {
    if (command_error.empty() && (!path || !path->command(record, command_error))) {
      command_error = command_error.empty() ? "a machine target before the job's start record" : command_error;
      command_error = journal_path + ": " + command_error;
    }
  };
  const journal::JournalReadResult read = journal::read_journal_file(journal_path, visit);
  if (!read.ok) {
    error = read.error;
    return false;
  }
  if (!started || !path) {
    error = journal_path + ": no job's start record: not a job's journal";
    return false;
  }
  if (!tables_match) {
    char text[160];
    std::snprintf(text, sizeof text, ": recorded on other tables than these (CRC-32 %08" PRIx32 "): give the job's own --tables",
                  part.header.crc32);
    error = journal_path + text;
    return false;
  }
  if (job_config_crc32 != settings.config_crc32) {
    char ran[64] = "the compiled-in rig";
    if (job_config_crc32 != 0) {
      std::snprintf(ran, sizeof ran, "a configuration of CRC-32 %08" PRIx32, job_config_crc32);
    }
    error = journal_path + ": the job ran with " + ran +
            ", not this one: give its own --config (its home and its machine decide the path)";
    return false;
  }
  if (!command_error.empty()) {
    error = command_error;
    return false;
  }
  if (path->targets() == 0) {
    error = journal_path + ": the mill was given no target: nothing was cut, no program to write";
    return false;
  }
  summary.targets = path->targets();
  summary.legs = path->moves().size();
  const MergeResult merged = merge_collinear(path->moves(), settings.path.home_world_mm, part, settings.merge_tolerance_mm);
  summary.moves = merged.moves.size();
  summary.sweep_checks = merged.sweep_checks;
  Eigen::Vector3d at = settings.path.home_world_mm;
  for (const CutMove& move : merged.moves) {
    summary.feed_length_mm += move.kind == MoveKind::Feed ? (move.to_mm - at).norm() : 0.0;
    at = move.to_mm;
  }
  Eigen::Vector3d start = settings.path.home_world_mm;
  std::vector<CutMove> moves = merged.moves;
  ProgramSettings program = settings.program;
  if (settings.machine_coordinates) {
    const Eigen::Vector3d home = settings.path.home_world_mm;
    const auto machine = [&](const Eigen::Vector3d& world) {
      Eigen::Vector3d m;
      for (int i = 0; i < 3; ++i) {
        m[i] = settings.machine_sign[static_cast<std::size_t>(i)] * (world[i] - home[i]);
      }
      return m;
    };
    for (CutMove& move : moves) {
      move.to_mm = machine(move.to_mm);
    }
    start = machine(start);
    program.safe_z_mm = 0.0;  // home's height: the top of the travel
    program.motion_prefix = "G53 ";
  }
  program.tool = tool_name(part);
  char tables_line[160];
  std::snprintf(tables_line, sizeof tables_line, "tables CRC-32 %08" PRIx32 ", %" PRIu32 " triangles; tool: %s", part.header.crc32,
                part.header.triangle_count, program.tool.c_str());
  char merge_line[200];
  std::snprintf(merge_line, sizeof merge_line,
                "%" PRIu64 " machine targets, %" PRIu64 " legs; collinear runs merged within %.4f mm, each merge off "
                "the path checked legal",
                summary.targets, summary.legs, settings.merge_tolerance_mm);
  program.comments.insert(program.comments.begin(),
                          {"the legal cut of " + settings.source_name + ", as the mill was commanded", tables_line,
                           settings.machine_coordinates
                               ? "mm, absolute, the machine's own coordinates, G53 on every move: 0 at home"
                               : "mm, absolute, work coordinates: set G54 so that the part's origin is X0 Y0 Z0",
                           "feeds from the recorded timing; backlash take-ups left out: the controller compensates its own",
                           merge_line});
  const std::string temporary = out_path + ".partial";
  std::FILE* out = std::fopen(temporary.c_str(), "w");
  if (out == nullptr) {
    error = out_path + ": cannot be written";
    return false;
  }
  const bool written = write_program(out, moves, start, program);
  const bool closed = std::fclose(out) == 0;
  if (!written || !closed || std::rename(temporary.c_str(), out_path.c_str()) != 0) {
    std::remove(temporary.c_str());
    error = out_path + ": could not be written in full (disk full?)";
    return false;
  }
  return true;
}

}  // namespace stencil::gcode
