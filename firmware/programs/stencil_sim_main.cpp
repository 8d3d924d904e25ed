// stencil-sim: the controller's cycle and machine side against the simulated device, the fake CY545
// on a pseudo-terminal and the simulated mill, on the baked-in sample part or a table file; reports
// gouges, coverage and loop timing.
#include <algorithm>
#include <cinttypes>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <signal.h>
#include <unistd.h>

#include <atomic>

#include <CLI/CLI.hpp>

#include "board/sim/fault_injection.hpp"
#include "board/sim/sim_job.hpp"
#include "board/sim/sim_report.hpp"
#include "firmware/services/report/build_version.hpp"
#include "firmware/services/report/job_folder.hpp"
#include "firmware/programs/display_option.hpp"
#include "firmware/programs/output_probe.hpp"
#include "board/sherline_suzuki/table_fit.hpp"
#include "board/sim/simulated_commissioning.hpp"
#include "firmware/programs/sim_options.hpp"
#include "firmware/programs/table_file.hpp"
#include "firmware/runtime/realtime_thread.hpp"
#include "board/sim/gcode_job.hpp"
#include "firmware/services/gcode/journal_gcode.hpp"
#include "firmware/services/journal/job_journal.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/core/tables/table_loader.hpp"

// The baked-in sample part (the hex prism), linked into its own read-only section.
extern const unsigned char stencil_table_hex_prism[];
extern const std::size_t stencil_table_hex_prism_size;

namespace {

using namespace stencil;

constexpr int kExitDone = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitSafeState = 3;

// Set by SIGINT, SIGTERM, SIGHUP and SIGQUIT: the run ends through the cycle's safe state (a stop command).
std::atomic<bool> interrupted{false};

void on_signal(int) { interrupted.store(true); }

int bad_input(const std::string& message) {
  std::fprintf(stderr, "stencil-sim: %s\n", message.c_str());
  return kExitBadInput;
}

// "X0,Y0,Z0,X1,Y1,Z1" in world mm, inside the workspace, low below high.
bool parse_stock(const std::string& text, const tables::PartTables& part, sim::StockBox& stock, std::string& error) {
  std::vector<double> values;
  std::stringstream fields(text);
  std::string field;
  while (std::getline(fields, field, ',')) {
    double value = 0.0;
    if (!sim::parse_finite_field(field, value)) {
      error = "--stock " + text + ": '" + field + "' is not a number; expected X0,Y0,Z0,X1,Y1,Z1 in mm";
      return false;
    }
    values.push_back(value);
  }
  if (values.size() != 6) {
    error = "--stock " + text + ": " + std::to_string(values.size()) + " numbers; expected X0,Y0,Z0,X1,Y1,Z1 in mm";
    return false;
  }
  stock = {{values[0], values[1], values[2]}, {values[3], values[4], values[5]}};
  for (int axis = 0; axis < 3; ++axis) {
    if (!(stock.low_mm[axis] < stock.high_mm[axis]) || stock.low_mm[axis] < 0.0 ||
        stock.high_mm[axis] > part.header.workspace_mm[axis]) {
      error = "--stock " + text + ": axis " + "xyz"[axis] + " must have 0 <= low < high <= the workspace's " +
              std::to_string(part.header.workspace_mm[axis]) + " mm";
      return false;
    }
  }
  return true;
}

// The picture goes beside the report, as .png.
std::string picture_path_of(const std::string& report_path) {
  return (report_path.size() > 5 && report_path.compare(report_path.size() - 5, 5, ".json") == 0
              ? report_path.substr(0, report_path.size() - 5)
              : report_path) +
         ".png";
}

// One run of a journal (0: the first, 1 the first resume, ...): its cycles and the commands they took.
bool read_run(const std::string& path, std::uint32_t run, std::size_t good_bytes, std::vector<journal::RecordedCycle>& records,
              std::vector<control::CommandEvent>& commands, std::string& error) {
  std::uint32_t in_run = 0;
  journal::JournalVisitor keep;
  keep.resume = [&](const journal::JournalResume&) { ++in_run; };
  keep.cycle = [&](const journal::RecordedCycle& r) {
    if (in_run == run) {
      records.push_back(r);
    }
  };
  keep.command = [&](const control::CommandEvent& e) {
    if (in_run == run) {
      commands.push_back(e);
    }
  };
  const journal::JournalReadResult read = journal::read_journal_file(path, keep, good_bytes);
  error = read.error;
  return read.ok;
}

// How many of the recorded commands the replay did not take the same way: at the same cycle, to the
// same outcome and value (a stop the replay itself adds, for a safe state the record gives no command
// for, aside).
std::size_t commands_differing_from(const std::vector<control::CommandEvent>& recorded,
                                    const std::vector<control::CommandEvent>& taken) {
  std::vector<control::CommandEvent> replayed;
  for (const control::CommandEvent& e : taken) {
    if (e.source != control::CommandSource::Replay) {
      replayed.push_back(e);
    }
  }
  std::size_t differing = 0;
  for (std::size_t i = 0; i < std::max(replayed.size(), recorded.size()); ++i) {
    const bool both = i < replayed.size() && i < recorded.size();
    const bool equal = both && replayed[i].cycle == recorded[i].cycle && replayed[i].kind == recorded[i].kind &&
                       replayed[i].outcome == recorded[i].outcome &&
                       std::memcmp(&replayed[i].applied, &recorded[i].applied, sizeof(double)) == 0;
    differing += equal ? 0 : 1;
  }
  return differing;
}

// --replay: every run the journal holds, in turn, each from the state the runs before it left.
int replay(const std::string& path, const tables::PartTables& part, board::sim::SimJob job, const std::string& report_path,
           const std::string& stock_csv_path, double pace, const report::Provenance& provenance) {
  journal::JobHistory history;
  std::string error;
  if (!journal::read_job_history(path, part.header.crc32, part.header.triangle_count, board::sim::frames(job.rig), {}, history,
                                 error)) {
    return bad_input("--replay: " + error);
  }
  // The stock the job was recorded on, from its start record.
  const std::size_t at = history.start.job.find("stock=");
  double box[6];
  if (at == std::string::npos || std::sscanf(history.start.job.c_str() + at, "stock=%lf,%lf,%lf,%lf,%lf,%lf", &box[0], &box[1],
                                             &box[2], &box[3], &box[4], &box[5]) != 6) {
    return bad_input("--replay " + path + ": its start record names no stock (\"" + history.start.job + "\")");
  }
  job.stock = {{box[0], box[1], box[2]}, {box[3], box[4], box[5]}};
  job.pace = pace;
  job.until_complete = false;
  std::printf("replay: %s: %u run(s), %llu cycles (%s)\n", path.c_str(), history.segments,
              static_cast<unsigned long long>(history.cycles), history.start.job.c_str());
  board::sim::SimResult result;
  bool all_same = true;
  const app::CpuLatencyHold latency_hold;
  for (std::uint32_t run = 0; run < history.segments; ++run) {
    std::vector<journal::RecordedCycle> records;
    std::vector<control::CommandEvent> commands;
    if (!read_run(path, run, history.good_bytes, records, commands, error)) {
      return bad_input("--replay: " + error);
    }
    job.replay = &records;
    job.replay_commands = &commands;
    job.resume_from = run == 0 ? "" : path;
    job.resume_bytes = run == 0 ? 0 : history.run_starts[run - 1];
    result = board::sim::run_fast(job);
    if (!result.started) {
      std::fprintf(stderr, "stencil-sim: %s\n", result.error.c_str());
      return kExitSafeState;
    }
    const bool reason_same = !control::is_device_reason(result.replay_recorded_reason) ||
                             result.safe_state == result.replay_recorded_reason;
    const std::size_t commands_differing = commands_differing_from(commands, result.operator_record.commands);
    const bool same = result.replay_mismatches == 0 && result.replay_cycles == records.size() && reason_same &&
                      result.replay_commands_not_given == 0 && commands_differing == 0;
    all_same = all_same && same;
    std::printf("replay run %u: %llu of %zu recorded cycles, %zu recorded commands (%zu taken otherwise), %llu cycles "
                "with a different virtual tool%s; recorded ending %s, replayed %s: %s\n",
                run, static_cast<unsigned long long>(result.replay_cycles), records.size(), commands.size(), commands_differing,
                static_cast<unsigned long long>(result.replay_mismatches),
                result.replay_first_mismatch >= 0 ? (" (the first at cycle " + std::to_string(result.replay_first_mismatch) + ")").c_str() : "",
                control::safe_reason_name(result.replay_recorded_reason), control::safe_reason_name(result.safe_state),
                same ? "the same" : "DIFFERENT");
  }
  std::printf("%s", board::sim::summary(result).c_str());
  const std::string picture_path = picture_path_of(report_path);
  if (!board::sim::write_report_json(report_path, result, provenance, error) || !board::sim::write_picture_png(picture_path, result, error) ||
      (!stock_csv_path.empty() && !board::sim::write_stock_csv(stock_csv_path, result, error))) {
    return bad_input(error);
  }
  std::printf("report: %s\npicture: %s\n", report_path.c_str(), picture_path.c_str());
  std::printf("replay: %s\n", all_same ? "every run replayed as recorded" : "the replay differs from the record");
  return all_same ? kExitDone : kExitSafeState;
}


// The part: a table file read into `file_bytes`, or the baked-in section used in place.
bool load_part(const std::string& tables_path, std::vector<unsigned char>& file_bytes, tables::PartTables& part,
               std::string& error) {
  if (tables_path.empty()) {
    const tables::TableLoadResult loaded =
        tables::load_tables({reinterpret_cast<const std::byte*>(stencil_table_hex_prism), stencil_table_hex_prism_size}, part);
    if (!loaded.ok) {
      error = std::string("the baked-in table does not load: ") + loaded.field;
    }
    return loaded.ok;
  }
  return app::load_table_file(tables_path, file_bytes, part, error);
}

Eigen::Vector3d sim_home(const board::sim::SimRig& rig) {
  return {rig.home_world_mm[0], rig.home_world_mm[1], rig.home_world_mm[2]};
}

// The scripted hand moves a little slower than the virtual tool may (0.8 of it), so that the virtual
// tool keeps up with it and a scripted job is not a tug against the speed limit.
double operator_speed_mm_per_s(const board::sim::SimRig& rig) { return 0.8 * rig.facts.virtual_tool_speed_mm_per_s; }

// --commission: the simulated rig commissioned; what it found, and 0 when nothing, else 3.
int commission(const app::SimOptions& o, const board::sim::SimJob& job) {
  const board::sherline_suzuki::CommissioningResult result = board::sim::commission_simulated_rig(
      job, o.commissioning, &interrupted, [](const std::string& line) { std::printf("%s\n", line.c_str()); });
  std::printf("%s", board::sherline_suzuki::describe(result).c_str());
  return result.passed ? 0 : kExitSafeState;
}

// The tables against the configured rig (its travel from the work offset, the device's reach).
bool fits_the_rig(const app::SimOptions& o, const tables::PartTables& part, std::string& error) {
  const std::string name = o.tables_path.empty() ? std::string("the baked-in hex prism") : o.tables_path;
  return board::sherline_suzuki::check_tables_fit(part.header, name, o.rig.facts, {o.rig.home_world_mm, 0.0, 0.0}, error);
}

// The job the options describe: its stock, the operator's script and, in `job_text`, what makes it
// the same job when it is resumed (recorded at its start, checked on resume).
bool make_job(const app::SimOptions& o, const tables::PartTables& part, board::sim::SimJob& job, std::string& job_text,
              sim::GcodeProgram& program, std::string& error) {
  job.part = &part;
  job.rig = o.rig;
  job.linuxcnc = o.linuxcnc;
  job.stock = board::sim::default_stock(part);
  if (!o.stock_text.empty() && !parse_stock(o.stock_text, part, job.stock, error)) {
    return false;
  }
  const std::string& gcode_path = o.gcode_operator_path.empty() ? o.gcode_direct_path : o.gcode_operator_path;
  if (!gcode_path.empty()) {
    sim::GcodeReadOptions read;
    read.arc_tolerance_mm = o.gcode_arc_tolerance_mm;
    if (!sim::read_gcode_program(gcode_path, read, program, error)) {
      return false;
    }
    job.script = board::sim::gcode_script(program, sim_home(job.rig), operator_speed_mm_per_s(job.rig),
                                          job.rig.facts.haptic_to_machine_scale);
  } else if (!o.operator_path.empty()) {
    if (!sim::read_operator_csv(o.operator_path, job.script, error)) {
      return false;
    }
  } else {
    const sim::Pattern pattern = o.pattern_name == "raster"    ? sim::Pattern::Raster
                                 : o.pattern_name == "plunge"   ? sim::Pattern::Plunge
                                 : o.pattern_name == "thinwall" ? sim::Pattern::Thinwall
                                                                : sim::Pattern::Random;
    job.script = sim::make_pattern(pattern, job.stock, sim_home(job.rig), operator_speed_mm_per_s(job.rig),
                                   job.rig.facts.haptic_to_machine_scale, o.seed, board::sim::touch_tip_of(part, job.stock),
                                   o.moves);
  }
  char numbers[200];
  std::snprintf(numbers, sizeof numbers, " seed=%llu moves=%d stock=%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                static_cast<unsigned long long>(o.seed), o.moves, job.stock.low_mm.x(), job.stock.low_mm.y(),
                job.stock.low_mm.z(), job.stock.high_mm.x(), job.stock.high_mm.y(), job.stock.high_mm.z());
  const std::string operator_text = !o.gcode_operator_path.empty() ? "gcode:" + o.gcode_operator_path
                                    : o.operator_path.empty()        ? std::string("-")
                                                                     : o.operator_path;
  job_text = "tables=" + (o.tables_path.empty() ? std::string("(baked-in hex prism)") : o.tables_path) +
             " operator=" + operator_text + " pattern=" + (operator_text == "-" ? o.pattern_name : std::string("-")) + numbers;
  // A configured rig (and a mill truth of its own) make it another job; the compiled-in rig's text is as before.
  char files[64] = "";
  if (o.config_crc32 != 0 || o.mill_truth_crc32 != 0) {
    std::snprintf(files, sizeof files, " config-crc32=%08x mill-truth-crc32=%08x", o.config_crc32, o.mill_truth_crc32);
  }
  job_text += files;
  // A dynamic hand is another operator (the placed hand's text is as before).
  for (const sim::HandParameters& hand : sim::kHandPresets) {
    if (o.hand == hand.name) {
      job.hand = hand;
      job_text += " hand=" + o.hand;
    }
  }
  // The wall's feel as the operator's commands before the first cycle; none given, none sent. Part of
  // the job: a resume must give the same (the text is as before without them).
  constexpr auto kProgram = control::CommandSource::Program;
  char feel[96] = "";
  if (o.damping_n_s_per_m > 0.0) {
    job.opening_commands.push_back({control::CommandKind::SetDamping, o.damping_n_s_per_m, kProgram});
    std::snprintf(feel, sizeof feel, " damping=%.17g", o.damping_n_s_per_m);
    job_text += feel;
  }
  if (o.friction > 0.0) {
    job.opening_commands.push_back({control::CommandKind::SetFriction, o.friction, kProgram});
    std::snprintf(feel, sizeof feel, " friction=%.17g", o.friction);
    job_text += feel;
  }
  if (o.speed_limiting == "penalty") {
    job.opening_commands.push_back({control::CommandKind::SetSpeedLimiting, 1.0, kProgram});
    job_text += " speed_limiting=penalty";
  }
  if (job_text.size() > 1024) {
    error = "--tables and --operator: paths too long to record in the journal (" + std::to_string(job_text.size()) +
            " bytes of the job; at most 1024)";
    return false;
  }
  return true;
}

// --resume: a first look at the journal (is it this job, and where did it stop?); the operator's
// script carries on from there, the rebuild is the job's. Fills in the journal's Resume record.
bool prepare_resume(app::SimOptions& o, const tables::PartTables& part, const std::string& job_text,
                    board::sim::SimJob& job, journal::JobJournalRequest& request, std::string& error) {
  journal::JobHistory history;
  if (!journal::read_job_history(o.resume_path, part.header.crc32, part.header.triangle_count, board::sim::frames(job.rig), {},
                                 history, error)) {
    error = "--resume: " + error;
    return false;
  }
  if (history.start.job != job_text) {
    error = "--resume " + o.resume_path + ": recorded for another job (" + history.start.job + "); this one is " +
            job_text + ": resume with the recorded job's options";
    return false;
  }
  if (!history.tail.empty()) {
    std::printf("resume: %s: ignoring its torn tail (%s)\n", o.resume_path.c_str(), history.tail.c_str());
  }
  // Where the cut stopped: the mill's last target (the stock is cut there), else the virtual tool.
  const Eigen::Vector3d rejoin = history.machine_commands > 0 ? history.last_commanded_tip_mm : history.last_virtual_tip_mm;
  double approach_s = 0.0;
  job.script = sim::carry_on(job.script, history.script_s, sim_home(job.rig), rejoin, operator_speed_mm_per_s(job.rig),
                             job.rig.facts.haptic_to_machine_scale, approach_s);
  request.resume.segment = history.segments;
  request.resume.script_s = history.script_s;
  request.resume.approach_s = approach_s;
  request.resume_bytes = history.good_bytes;
  if (o.duration_s > 0.0) {
    o.duration_s = approach_s + std::max(0.0, o.duration_s - history.script_s);
  }
  std::printf("resume: %s: %u run(s), %llu cycles, %zu safe state(s), %llu machine commands; the script carries on "
              "from %.3f s after %.1f s back to (%.3f, %.3f, %.3f) mm\n",
              o.resume_path.c_str(), history.segments, static_cast<unsigned long long>(history.cycles),
              history.faults.size(), static_cast<unsigned long long>(history.machine_commands), history.script_s,
              approach_s, rejoin.x(), rejoin.y(), rejoin.z());
  job.resume_from = o.resume_path;
  job.resume_bytes = history.good_bytes;
  return true;
}

// Where this run writes: a new job's own folder (retention first, then the folder made), or for
// --resume and --replay their journal's folder. The report and the journal land in it unless given;
// the other outputs when given as bare names. A new job with every output given makes no folder
// (unless --out-dir asks for one). False with the message: nothing has run.
bool place_outputs(app::SimOptions& o, std::uint32_t resume_segment, report::JobFolder& folder, std::string& error) {
  std::string* const side_outputs[] = {&o.trace_path, &o.stock_csv_path, &o.device_log_path, &o.script_csv_path};
  const bool bare_side_output = std::any_of(std::begin(side_outputs), std::end(side_outputs), [](const std::string* path) {
    return !path->empty() && path->find('/') == std::string::npos;
  });
  std::string report_name = "report.json";
  if (!o.replay_path.empty() || !o.resume_path.empty()) {
    folder.use_folder_of(o.replay_path.empty() ? o.resume_path : o.replay_path);
    report_name = o.replay_path.empty() ? "report-resume-" + std::to_string(resume_segment) + ".json" : "replay.json";
  } else if (!o.jobs.out_dir.empty() || o.report_path.empty() || (o.journal_path.empty() && !o.no_journal) || bare_side_output) {
    if (!app::make_job_folder(o.jobs, "stencil-sim", o.output_folder, folder,
                              [](const std::string& line) { std::printf("%s\n", line.c_str()); }, error)) {
      return false;
    }
    std::printf("job folder: %s\n", folder.path().c_str());
    if (!o.no_journal && o.journal_path.empty()) {
      o.journal_path = folder.place("", "job.journal");
    }
  }
  if (o.report_path.empty()) {
    o.report_path = folder.place("", report_name);
  }
  for (std::string* path : side_outputs) {
    *path = folder.place(*path, "");
  }
  return true;
}

// The files a run writes besides its report and journal, closed when the program ends.
struct SideFiles {
  std::FILE* trace = nullptr;
  std::FILE* device_log = nullptr;
  SideFiles() = default;
  SideFiles(const SideFiles&) = delete;
  SideFiles& operator=(const SideFiles&) = delete;
  ~SideFiles() { close(); }
  void close() {
    for (std::FILE** file : {&trace, &device_log}) {
      if (*file != nullptr) {
        std::fclose(*file);
        *file = nullptr;
      }
    }
  }
};

bool open_trace(const app::SimOptions& o, board::sim::SimJob& job, SideFiles& files, std::string& error) {
  if (o.trace_path.empty()) {
    return true;
  }
  files.trace = std::fopen(o.trace_path.c_str(), "w");
  if (files.trace == nullptr) {
    error = o.trace_path + ": cannot be written";
    return false;
  }
  std::fprintf(files.trace, "t_s,x_mm,y_mm,z_mm\n");
  job.trace = files.trace;
  return true;
}

// The outputs can be written: found out now, not after the whole simulated job (every input has
// been checked by now, so bad input leaves no report behind); the device's log is opened.
bool check_outputs(const app::SimOptions& o, board::sim::SimJob& job, SideFiles& files, std::string& error) {
  for (const std::string& path : {o.report_path, picture_path_of(o.report_path)}) {
    if (!app::probe_writable(path, error)) {
      return false;
    }
  }
  if (!o.device_log_path.empty()) {
    files.device_log = std::fopen(o.device_log_path.c_str(), "w");
    if (files.device_log == nullptr) {
      error = o.device_log_path + ": cannot be written";
      return false;
    }
    job.device_process_log = files.device_log;
  }
  return true;
}

void print_banner(const app::SimOptions& o, const board::sim::SimJob& job) {
  const std::string motion = !o.gcode_operator_path.empty() ? "the G-code program " + o.gcode_operator_path
                             : o.operator_path.empty()      ? o.pattern_name + " pattern"
                                                            : o.operator_path + " pattern";
  std::printf("stencil-sim: %s, %s over the stock [%.1f,%.1f]x[%.1f,%.1f]x[%.1f,%.1f] mm, %.0f simulated s\n",
              o.tables_path.empty() ? "the baked-in hex prism" : o.tables_path.c_str(), motion.c_str(), job.stock.low_mm.x(),
              job.stock.high_mm.x(), job.stock.low_mm.y(), job.stock.high_mm.y(), job.stock.low_mm.z(),
              job.stock.high_mm.z(), job.script.duration_s());
  std::fflush(stdout);
}

board::sim::SimResult run(const app::SimOptions& o, board::sim::SimJob& job) {
  if (!o.real_time()) {
    job.pace = o.fast ? 0.0 : o.speed;
    // Every machine update is a few round trips over the pty, each of which wakes a CPU: kept out
    // of deep idle states for the run, the demo job takes about a third less wall time here.
    const app::CpuLatencyHold latency_hold;
    return board::sim::run_fast(job);
  }
  // The machine, fake CY545 and records threads start after this and inherit it: the cycle's
  // CPU is left to the cycle.
  if (o.cpu >= 0 && !app::keep_off_cpu(o.cpu)) {
    std::fprintf(stderr, "stencil-sim: the other threads could not be kept off CPU %d; they share it with the cycle\n", o.cpu);
  }
  return board::sim::run_realtime(job, app::realtime_runner({o.priority, o.cpu, o.require_rt}, [](const std::string& line) {
                                    std::fprintf(stderr, "stencil-sim: %s\n", line.c_str());
                                  }));
}

// After the run: the journal ended in order (or, when nothing ran, every output of this run undone),
// the summary, the report, the picture and the stock's heights. The program's exit status.
// The report, its picture and (when asked) the stock's heights; said where they went. False with
// `error` naming what could not be written.
bool write_outputs(const app::SimOptions& o, const board::sim::SimResult& result, const report::Provenance& provenance,
                   std::string& error) {
  const std::string picture_path = picture_path_of(o.report_path);
  if (!board::sim::write_report_json(o.report_path, result, provenance, error) ||
      !board::sim::write_picture_png(picture_path, result, error) ||
      (!o.stock_csv_path.empty() && !board::sim::write_stock_csv(o.stock_csv_path, result, error))) {
    return false;
  }
  std::printf("report: %s\npicture: %s\n", o.report_path.c_str(), picture_path.c_str());
  return true;
}

// --gcode-direct: the program's moves cut into the stock with no controller; the report, picture and
// stock heights as a job's, in the job's folder.
int cut_directly(app::SimOptions& o, const tables::PartTables& part, const board::sim::SimJob& job,
                 const sim::GcodeProgram& program, const report::Provenance& provenance) {
  std::string error;
  report::JobFolder folder;
  if (!place_outputs(o, 0, folder, error)) {
    return bad_input(error);
  }
  board::sim::SimResult result;
  const auto wall_start = std::chrono::steady_clock::now();
  board::sim::cut_directly(part, job.stock, board::sim::true_frames(job.rig), program, sim_home(job.rig), result);
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  result.gcode_program = o.gcode_direct_path;
  result.gcode_direct = true;
  std::printf("gcode-direct: %s, %zu moves cut with no stencil\n", o.gcode_direct_path.c_str(), program.moves.size());
  std::printf("gouge: %s mm deepest, %.3f mm3 under the part's top\nstock removed %.1f mm3\n",
              result.gouge_measured ? std::to_string(result.gouge_max_depth_mm).c_str() : "not measured (not a ball end mill)",
              result.gouge_volume_mm3, result.removed_volume_mm3);
  return write_outputs(o, result, provenance, error) ? kExitDone : bad_input(error);
}

// --gcode: the program from the journal just closed, as stencil-journal gcode writes it.
bool write_gcode(const app::SimOptions& o, const tables::PartTables& part, const std::string& journal_path,
                 std::string& error) {
  gcode::JournalExport settings;
  const motion::PlannerLimits limits = board::sherline_suzuki::planner_limits(o.rig.facts);
  settings.path.path = limits.path;
  settings.path.update_s = limits.update_period_s;
  settings.path.home_world_mm = sim_home(o.rig);
  settings.program.safe_z_mm = o.rig.home_world_mm[2];
  settings.source_name = journal_path;
  settings.config_crc32 = o.config_crc32;
  gcode::ExportSummary summary;
  if (!gcode::export_journal_gcode(journal_path, part, settings, o.gcode_path, summary, error)) {
    return false;
  }
  std::printf("gcode: %s (%" PRIu64 " moves from %" PRIu64 " machine targets)\n", o.gcode_path.c_str(), summary.moves,
              summary.targets);
  return true;
}

int finish(const app::SimOptions& o, const tables::PartTables& part, board::sim::SimResult& result, const journal::JobJournalRequest& request,
           journal::JournalWriter& journal_writer, const std::string& journal_path, const report::Provenance& provenance,
           report::JobFolder& folder) {
  std::string error;
  if (!result.started) {
    if (!journal::undo_unrun_job_journal(request, journal_writer, journal_path)) {
      std::fprintf(stderr, "stencil-sim: %s: could not be cut back to the job it held\n", o.resume_path.c_str());
    }
    if (!o.trace_path.empty()) {
      std::remove(o.trace_path.c_str());
    }
    folder.abandon();
    std::fprintf(stderr, "stencil-sim: %s\n", result.error.c_str());
    return result.error.rfind("--require-rt", 0) == 0 ? kExitBadInput : kExitSafeState;
  }
  if (journal_writer.is_open() || !journal_writer.error().empty()) {
    // The run ended in order: said in the journal, so a resume can tell it from a kill.
    static_cast<void>(journal_writer.append_end(result.cycles, result.safe_state));
    const bool closed = journal_writer.close();
    result.journal_path = journal_path;
    result.journal_records = journal_writer.cycle_records();
    result.journal_machine_records = journal_writer.machine_records();
    result.journal_command_records = journal_writer.command_records();
    result.journal_error = closed ? "" : journal_writer.error();
  }
  std::printf("%s", board::sim::summary(result).c_str());
  if (!write_outputs(o, result, provenance, error)) {
    return bad_input(error);
  }
  if (!o.gcode_path.empty() && !write_gcode(o, part, journal_path, error)) {
    return bad_input("--gcode: " + error);
  }
  // A journal that lost records is not a job done, even if the cut itself ended well.
  return result.safe_state == control::SafeReason::None && result.journal_error.empty() ? kExitDone : kExitSafeState;
}

}  // namespace

int main(int argc, char** argv) {
  // From the start: a signal while the job is being prepared still ends it through the cycle's
  // stop, with its report and journal, once it runs.
  struct sigaction action {};
  action.sa_handler = on_signal;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {  // as stencil-rig: a closed terminal too
    sigaction(signal_number, &action, nullptr);
  }
  CLI::App app{
      "stencil-sim: the haptic stencil controller's cycle and machine side against a simulated operator and\n"
      "device, the fake CY545 stepper controller on a pseudo-terminal and a simulated mill that removes\n"
      "material; reports gouges, coverage and loop timing. Each job writes in a folder of its own (--out-dir):\n"
      "its journal, report and picture; a --resume of it writes there too. Exit status: 0 done, 2 bad input\n"
      "(a jobs folder that cannot be written among it: nothing ran), 3 ended in a safe state."};
  app.set_version_flag("--version", report::version_text("stencil-sim"));
  app::SimOptions o;
  app::add_sim_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), kExitBadInput);
  }
  std::string error;
  std::vector<unsigned char> file_bytes;
  tables::PartTables part{};
  board::sim::SimJob job;
  std::string job_text;
  sim::GcodeProgram program;
  if (!app::check_sim_options(app, o, error) || !app::apply_sim_config(app, o, error) ||
      !load_part(o.tables_path, file_bytes, part, error) || !fits_the_rig(o, part, error) ||
      !make_job(o, part, job, job_text, program, error) ||
      !board::sherline_suzuki::check_stock_fit({job.stock.low_mm.x(), job.stock.low_mm.y(), job.stock.low_mm.z()},
                                               {job.stock.high_mm.x(), job.stock.high_mm.y(), job.stock.high_mm.z()},
                                               o.rig.facts, {o.rig.home_world_mm, 0.0, 0.0}, error)) {
    return bad_input(error);
  }
  if (o.commission) {
    return commission(o, job);
  }
  report::Provenance provenance;
  provenance.program = "stencil-sim";
  provenance.command_line.assign(argv, argv + argc);
  provenance.configuration = o.config_path;
  provenance.configuration_crc32 = o.config_crc32;
  provenance.tables = o.tables_path.empty() ? std::string("(baked-in hex prism)") : o.tables_path;
  provenance.tables_crc32 = part.header.crc32;
  provenance.triangle_count = part.header.triangle_count;
  if (!o.gcode_direct_path.empty()) {
    return cut_directly(o, part, job, program, provenance);
  }
  report::JobFolder folder;
  // Before a replay too: the wall's feel weighs the force by the link's delay, so a job run over PIO
  // or CAN with the feel on is replayed with the same --haptic-transport for the same forces.
  job.transport = o.transport == "pio"   ? board::sim::HapticTransport::Pio
                  : o.transport == "can" ? board::sim::HapticTransport::Can
                                         : board::sim::HapticTransport::Direct;
  if (!o.replay_path.empty()) {
    return place_outputs(o, 0, folder, error)
               ? replay(o.replay_path, part, job, o.report_path, o.stock_csv_path, o.fast ? 0.0 : o.speed, provenance)
               : bad_input(error);
  }
  journal::JobJournalRequest request;
  request.program = "stencil-sim";
  request.none = o.no_journal;
  request.resume_path = o.resume_path;
  request.start.tables_crc32 = part.header.crc32;
  request.start.triangle_count = part.header.triangle_count;
  request.start.job = job_text;
  request.provenance = report::provenance_line(provenance);
  if ((!o.resume_path.empty() && !prepare_resume(o, part, job_text, job, request, error)) ||
      !place_outputs(o, request.resume.segment, folder, error)) {
    return bad_input(error);
  }
  request.path = o.journal_path;
  // From here a refusal undoes the job's folder made for this run (when nothing else is in it).
  const auto refuse = [&folder](const std::string& message) {
    folder.abandon();
    return bad_input(message);
  };
  job.duration_s = o.duration_s;
  job.fault = o.fault;
  job.until_complete = o.until_complete;
  SideFiles files;
  if ((!o.script_csv_path.empty() && !sim::write_operator_csv(o.script_csv_path, job.script, error)) ||
      !open_trace(o, job, files, error)) {
    return refuse(error);
  }
  if (isatty(STDERR_FILENO) != 0) {
    job.progress = [&job](double t_s, double coverage) {
      std::fprintf(stderr, "\rstencil-sim: %.0f of %.0f simulated s, coverage %.1f %%   ", t_s, job.script.duration_s(),
                   100.0 * coverage);
    };
  }
  print_banner(o, job);
  journal::JournalWriter journal_writer;
  std::string journal_path;
  if (!check_outputs(o, job, files, error) || !journal::open_job_journal(request, journal_writer, journal_path, error)) {
    return refuse(error);
  }
  if (!journal_path.empty()) {
    job.journal = &journal_writer;
    std::printf("journal: %s%s\n", journal_path.c_str(), o.resume_path.empty() ? "" : " (carried on)");
    std::fflush(stdout);
  }
  // The display, before the job: a page opened now sees the job from its start.
  app::Display display;
  if (!display.start(o.display, part, board::sim::controller_config(o.real_time(), job.rig), "stencil-sim", error)) {
    // Nothing ran: no journal of it left behind (an empty job's folder would be kept as resumable).
    static_cast<void>(journal::undo_unrun_job_journal(request, journal_writer, journal_path));
    return refuse(error);
  }
  job.display = display.feed();
  job.interrupted = &interrupted;
  board::sim::SimResult result = run(o, job);
  if (!o.gcode_operator_path.empty()) {
    result.gcode_program = o.gcode_operator_path;
    result.gcode_refused = board::sim::refused_lines(part, program, sim_home(job.rig));
  }
  if (job.progress) {
    std::fprintf(stderr, "\n");
  }
  display.end("the job ended after " + std::to_string(result.cycles) + " cycles" +
              (result.safe_state == control::SafeReason::None
                   ? std::string(", not in a safe state")
                   : std::string(", in the safe state (") + control::safe_reason_name(result.safe_state) + ")"));
  display.stop();
  files.close();
  return finish(o, part, result, request, journal_writer, journal_path, provenance, folder);
}
