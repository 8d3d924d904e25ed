// stencil-journal: what a job's journal holds, read with the one reader the controllers use. For a
// machinist (how far did the job get, where did it stop, how big is it) and for the tests (every
// cycle, target and command is in the file, whatever the format packs it into).
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "board/sherline_suzuki/rig_config.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/programs/table_file.hpp"
#include "firmware/services/gcode/journal_gcode.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/report/build_version.hpp"

#if STENCIL_BAKED_TABLE
// The baked-in sample part (the hex prism), linked into its own read-only section.
extern const unsigned char stencil_table_hex_prism[];
extern const std::size_t stencil_table_hex_prism_size;
#endif

namespace {

using namespace stencil;

constexpr int kExitRead = 0;
constexpr int kExitUnreadable = 1;  // not a journal, or damaged (the reader's error on stderr)
constexpr int kExitUsage = 2;

struct Counts {
  std::uint32_t version = 0;
  std::uint64_t runs = 0, cycles = 0, tools_kept = 0, safe_states = 0, homings = 0, machine_commands = 0,
                commands = 0, ends = 0, provenance = 0;
  std::uint64_t first_cycle_of_run = 0, last_cycle = 0;
  control::SafeReason last_end = control::SafeReason::None;
  bool ended = false;  // the last run has its End record
};

void print_summary(const std::string& path, const Counts& c, const journal::JournalReadResult& read) {
  std::printf("journal: %s (version %u)\n", path.c_str(), c.version);
  std::printf("runs: %" PRIu64 " (%s)\n", c.runs,
              c.ended ? "the last ended in order" : "the last has no end record: interrupted, it may be resumed");
  std::printf("cycles: %" PRIu64 " (their tool kept whole in %" PRIu64 ")\n", c.cycles, c.tools_kept);
  std::printf("machine_commands: %" PRIu64 "\ncommands: %" PRIu64 "\nsafe_states: %" PRIu64 "\nhomings: %" PRIu64
              "\nends: %" PRIu64 "\nprovenance: %" PRIu64 "\n",
              c.machine_commands, c.commands, c.safe_states, c.homings, c.ends, c.provenance);
  std::printf("bytes: %zu whole, %zu torn tail%s%s\n", read.good_bytes, read.tail_bytes, read.tail.empty() ? "" : ": ",
              read.tail.c_str());
  std::printf("bytes_per_cycle: %.2f\n", c.cycles > 0 ? static_cast<double>(read.good_bytes) / static_cast<double>(c.cycles) : 0.0);
  if (c.ends > 0) {
    std::printf("last_end: %s\n", control::safe_reason_name(c.last_end));
  }
}

// Three numbers as a JSON array; one that is not finite (a device that sent NaN) as null.
std::string json_array(double a, double b, double c, const char* format) {
  std::string text = "[";
  for (const double v : {a, b, c}) {
    char number[40] = "null";
    if (std::isfinite(v)) {
      std::snprintf(number, sizeof number, format, v);
    }
    text.append(text.size() > 1 ? ", " : "").append(number);
  }
  return text.append("]");
}

// One line of JSON per cycle: what the cycle read and left (tip and force null where the journal kept
// only the tip's check: tool_kept false).
void print_cycle(const journal::RecordedCycle& cycle) {
  const control::JournalRecord& r = cycle.record;
  const std::string device = json_array(r.device_mm[0], r.device_mm[1], r.device_mm[2], "%.17g");
  const std::string tip = cycle.tool_recorded ? json_array(r.virtual_tip_mm[0], r.virtual_tip_mm[1], r.virtual_tip_mm[2], "%.17g")
                                              : "null";
  const std::string force = cycle.tool_recorded ? json_array(static_cast<double>(r.force_n[0]), static_cast<double>(r.force_n[1]),
                                                             static_cast<double>(r.force_n[2]), "%.9g")
                                                : "null";
  std::printf("{\"cycle\": %" PRIu64 ", \"time_ns\": %" PRId64 ", \"device_mm\": %s, \"fresh\": %s, \"tool_kept\": %s, "
              "\"tip_mm\": %s, \"force_n\": %s, \"tip_check\": %" PRIu32 ", \"touched\": %" PRIu32 ", \"safe_state\": \"%s\"}\n",
              r.cycle, r.time_ns, device.c_str(), r.fresh ? "true" : "false", cycle.tool_recorded ? "true" : "false",
              tip.c_str(), force.c_str(), cycle.tip_check, r.touched_triangles, control::safe_reason_name(r.safe_reason));
}

int read(const std::string& path, bool cycles_json) {
  Counts c;
  journal::JournalVisitor visit;
  visit.start = [&](const journal::JournalStart&) { ++c.runs; };
  visit.resume = [&](const journal::JournalResume&) {
    ++c.runs;
    c.ended = false;
  };
  visit.cycle = [&](const journal::RecordedCycle& cycle) {
    ++c.cycles;
    c.tools_kept += cycle.tool_recorded ? 1 : 0;
    if (cycles_json) {
      print_cycle(cycle);
    }
  };
  visit.safe_state = [&](std::uint64_t, control::SafeReason) { ++c.safe_states; };
  visit.homed = [&](std::int64_t) { ++c.homings; };
  visit.machine_command = [&](const control::MachineCommandRecord&) { ++c.machine_commands; };
  visit.command = [&](const control::CommandEvent&) { ++c.commands; };
  visit.end = [&](std::uint64_t, control::SafeReason reason) {
    ++c.ends;
    c.ended = true;
    c.last_end = reason;
  };
  visit.provenance = [&](const std::string&) { ++c.provenance; };
  const journal::JournalReadResult result = journal::read_journal_file(path, visit);
  if (!result.ok) {
    std::fprintf(stderr, "stencil-journal: %s\n", result.error.c_str());
    return kExitUnreadable;
  }
  if (!cycles_json) {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    unsigned char header[12] = {};
    if (file != nullptr && std::fread(header, 1, sizeof header, file) == sizeof header) {
      for (int i = 3; i >= 0; --i) {
        c.version = c.version << 8U | header[8 + i];  // little-endian
      }
    }
    if (file != nullptr) {
      std::fclose(file);
    }
    print_summary(path, c, result);
  }
  return kExitRead;
}

struct GcodeOptions {
  std::string out_path;
  std::string tables_path;
  std::string config_path;
  double merge_tolerance_mm = 0.001;
  double spindle_rpm = 2800.0;
  std::string frame = "work";
};

bool load_part(const std::string& tables_path, std::vector<unsigned char>& bytes, tables::PartTables& part, std::string& error) {
  if (!tables_path.empty()) {
    return app::load_table_file(tables_path, bytes, part, error);
  }
#if STENCIL_BAKED_TABLE
  const tables::TableLoadResult loaded =
      tables::load_tables({reinterpret_cast<const std::byte*>(stencil_table_hex_prism), stencil_table_hex_prism_size}, part);
  if (!loaded.ok) {
    error = std::string("the baked-in table does not load: ") + loaded.field;
  }
  return loaded.ok;
#else
  error = "--tables: this build has no baked-in part: give the job's table file";
  return false;
#endif
}

// The journal's cut as a G-code program, on the job's own tables and rig (both checked against the
// journal: the rig's home and machine decide the path the mill was commanded).
int write_gcode(const std::string& journal_path, const GcodeOptions& o) {
  std::string error;
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  board::sherline_suzuki::RigConfig config;
  if (!load_part(o.tables_path, bytes, part, error) ||
      (!o.config_path.empty() && !board::sherline_suzuki::read_rig_config(o.config_path, config, error))) {
    std::fprintf(stderr, "stencil-journal: %s\n", error.c_str());
    return kExitUsage;
  }
  gcode::JournalExport settings;
  const motion::PlannerLimits limits = board::sherline_suzuki::planner_limits(config.facts);
  settings.path.path = limits.path;
  settings.path.update_s = limits.update_period_s;
  settings.path.home_world_mm = {config.work_offset_mm[0], config.work_offset_mm[1], config.work_offset_mm[2]};
  settings.program.safe_z_mm = config.work_offset_mm[2];
  settings.program.spindle_rpm = o.spindle_rpm;
  settings.merge_tolerance_mm = o.merge_tolerance_mm;
  settings.source_name = journal_path;
  settings.config_crc32 = o.config_path.empty() ? 0 : config.file_crc32;
  settings.machine_coordinates = o.frame == "machine";
  settings.machine_sign = config.facts.machine_sign;
  gcode::ExportSummary summary;
  if (!gcode::export_journal_gcode(journal_path, part, settings, o.out_path, summary, error)) {
    std::fprintf(stderr, "stencil-journal: %s\n", error.c_str());
    return kExitUnreadable;
  }
  std::printf("gcode: %s\ntargets: %" PRIu64 "\nlegs: %" PRIu64 "\nmoves_written: %" PRIu64 "\nfeed_length_mm: %.3f\n",
              o.out_path.c_str(), summary.targets, summary.legs, summary.moves, summary.feed_length_mm);
  return kExitRead;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"stencil-journal: what a job's journal holds (read as stencil-sim --resume and --replay read it)"};
  app.set_version_flag("--version", stencil::report::version_text("stencil-journal"));
  app.require_subcommand(1);
  std::string path;
  CLI::App* summary = app.add_subcommand("summary", "runs, cycles, machine targets, commands, safe states and ends "
                                                    "counted; the bytes and the bytes per cycle; a torn tail named");
  summary->add_option("journal", path, "the journal file")->required();
  CLI::App* cycles = app.add_subcommand("cycles", "every cycle as a line of JSON: cycle, time_ns, device_mm, fresh, "
                                                  "tip_mm and force_n (null where the journal kept only the tip's "
                                                  "CRC-32, tip_check), touched, safe_state");
  cycles->add_option("journal", path, "the journal file")->required();
  GcodeOptions gcode_options;
  CLI::App* gcode = app.add_subcommand(
      "gcode", "the path the mill was commanded as a G-code program any CNC can run: mm, absolute, the part's "
               "work coordinates, exact path (G61); feeds from the recorded timing; backlash take-ups left out; "
               "collinear runs merged, every merge off the recorded path checked legal on the job's tables");
  gcode->add_option("journal", path, "the job's journal")->required();
  gcode->add_option("-o,--output", gcode_options.out_path, "the program to write (.ngc)")->required();
  gcode->add_option("--tables", gcode_options.tables_path, "the job's .stbl (default: the baked-in hex prism)");
  gcode->add_option("--config", gcode_options.config_path,
                    "the job's rig configuration (default: the compiled-in rig): its home, and its machine's path "
                    "(the CY545's one-axis legs, LinuxCNC's straight segments)");
  gcode->add_option("--merge-tolerance", gcode_options.merge_tolerance_mm,
                    "mm a merged move may leave the recorded corners by (each such merge checked legal)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.1));
  gcode->add_option("--frame", gcode_options.frame,
                    "work: the part's coordinates (G54 set so that the part's origin is X0 Y0 Z0); machine: the "
                    "machine's own (G53 on every move, 0 at home, each axis counted as the configuration's "
                    "machine.axis_sign says), for a machine whose axes count against the part's")
      ->check(CLI::IsMember({"work", "machine"}))
      ->capture_default_str();
  gcode->add_option("--spindle-rpm", gcode_options.spindle_rpm, "the spindle speed written (S)")
      ->capture_default_str()->check(CLI::Range(1.0, 100000.0));
  app.footer("Exit status: 0 read (a torn tail is reported, not an error), 1 not a journal or damaged (the offset "
             "and what was expected on stderr), 2 usage.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), kExitUsage);  // --help and --version: 0
  }
  if (gcode->parsed()) {
    return write_gcode(path, gcode_options);
  }
  return read(path, cycles->parsed());
}
