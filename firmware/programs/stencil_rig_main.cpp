// stencil-rig: the controller on the real rig (board sherline_suzuki): the haptic device over the
// PIO shared-memory card or SocketCAN, the mill's CY545 over RS-232. It starts by checking
// everything it can (the host's real-time readiness, the tables, the serial port, the haptic link)
// and says plainly what is missing, then homes the mill and runs the cycle until SIGINT, SIGTERM, SIGHUP or SIGQUIT,
// --duration or a safe state, and stops the machine on the way out.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "board/sherline_suzuki/rig_devices.hpp"
#include "board/sherline_suzuki/rig_job.hpp"
#include "board/sherline_suzuki/rig_report.hpp"
#include "board/sherline_suzuki/table_fit.hpp"
#include "firmware/programs/display_option.hpp"
#include "firmware/programs/rig_control.hpp"
#include "firmware/programs/rig_options.hpp"
#include "firmware/programs/table_file.hpp"
#include "firmware/programs/terminal_commands.hpp"
#include "firmware/programs/terminal_machinist.hpp"
#include "firmware/runtime/realtime_thread.hpp"
#include "firmware/runtime/rt_readiness.hpp"
#include "firmware/services/display_link/display_link.hpp"
#include "firmware/services/gcode/journal_gcode.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/journal/job_journal.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "firmware/services/report/build_version.hpp"
#include "firmware/services/report/job_folder.hpp"

namespace {

using namespace stencil;
using board::sherline_suzuki::RigJob;
using board::sherline_suzuki::RigResult;

constexpr int kExitBadInput = 2;
constexpr int kExitNotStarted = 3;

int fail(int status, const std::string& message) {
  std::fprintf(stderr, "stencil-rig: %s\n", message.c_str());
  return status;
}

std::atomic<bool> interrupted{false};
void on_signal(int) { interrupted.store(true); }

// What makes the job the same job when it is resumed: recorded at its start, checked on resume.
// The rig's configuration counts too: a job resumed under another file would read its steps through
// other frames.
std::string job_text_of(const board::sherline_suzuki::WorkOffset& offset, const control::StockBlock& stock,
                        std::uint32_t config_crc32) {
  char text[340];
  std::snprintf(text, sizeof text,
                "work-offset=%.6f,%.6f,%.6f tool-stick-out=%.6f reference-stick-out=%.6f stock=%.6f,%.6f,%.6f,%.6f,%.6f,%.6f",
                offset.home_world_mm.x(), offset.home_world_mm.y(), offset.home_world_mm.z(), offset.tool_stick_out_mm,
                offset.reference_stick_out_mm, stock.low_mm.x(), stock.low_mm.y(), stock.low_mm.z(), stock.high_mm.x(),
                stock.high_mm.y(), stock.high_mm.z());
  char config[48];
  std::snprintf(config, sizeof config, config_crc32 == 0 ? " config=compiled-in" : " config-crc32=%08x", config_crc32);
  return std::string(text) + config;
}

// Where the job writes: a new job's own folder under the jobs folder (retention first, then the
// folder made; none when the report and the journal are both given or none is asked and no --out-dir),
// or a --resume's journal's folder. The report and journal land there unless given. False with the message.
bool place_outputs(app::RigOptions& o, std::uint32_t resume_segment, report::JobFolder& folder, std::string& error) {
  std::string report_name = "report.json";
  if (!o.resume_path.empty()) {
    folder.use_folder_of(o.resume_path);
    report_name = "report-resume-" + std::to_string(resume_segment) + ".json";
  } else if (!o.jobs.out_dir.empty() || o.report_path.empty() || (o.journal_path.empty() && !o.no_journal)) {
    if (!app::make_job_folder(o.jobs, "stencil-rig", o.config.output_folder, folder,
                              [](const std::string& line) { std::printf("stencil-rig: %s\n", line.c_str()); }, error)) {
      return false;
    }
    std::printf("stencil-rig: job folder %s\n", folder.path().c_str());
    if (!o.no_journal && o.journal_path.empty()) {
      o.journal_path = folder.place("", "job.journal");
    }
  }
  if (o.report_path.empty()) {
    o.report_path = folder.place("", report_name);
  }
  return true;
}

// The journal as asked: a fresh one, none, or (--resume) the job's own once it is found to be this
// job; the job's folder and its outputs' places before it (place_outputs). False with the message
// for the terminal.
bool open_journal(app::RigOptions& o, const tables::PartTables& part, const RigJob& job, report::JobFolder& folder,
                  journal::JobJournalRequest& request, journal::JournalWriter& writer, std::string& opened_path,
                  std::string& error) {
  request.program = "stencil-rig";
  request.none = o.no_journal;
  request.resume_path = o.resume_path;
  request.start.tables_crc32 = part.header.crc32;
  request.start.triangle_count = part.header.triangle_count;
  request.start.job = job_text_of(job.offset, job.stock, o.config.file_crc32);
  request.provenance = report::provenance_line(o.provenance);
  if (!o.resume_path.empty()) {
    journal::JobHistory history;
    if (!journal::read_job_history(o.resume_path, part.header.crc32, part.header.triangle_count,
                                   board::sherline_suzuki::rig_frames(job.offset, job.facts), {}, history, error)) {
      error = "--resume: " + error;
      return false;
    }
    if (history.start.job != request.start.job) {
      error = "--resume " + o.resume_path + ": recorded for another job (" + history.start.job + "); this one is " +
              request.start.job + ": resume with the recorded job's options";
      return false;
    }
    request.resume_bytes = history.good_bytes;
    request.resume.segment = history.segments;
    std::printf("stencil-rig: resuming %s: %u run(s), %llu cycles, %zu safe state(s), %llu machine commands%s\n",
                o.resume_path.c_str(), history.segments, static_cast<unsigned long long>(history.cycles),
                history.faults.size(), static_cast<unsigned long long>(history.machine_commands),
                history.tail.empty() ? "" : ("; its torn tail ignored (" + history.tail + ")").c_str());
  }
  if (!place_outputs(o, request.resume.segment, folder, error)) {
    return false;
  }
  request.path = o.journal_path;
  if (!journal::open_job_journal(request, writer, opened_path, error)) {
    folder.abandon();
    return false;
  }
  if (o.resume_path.empty() && !opened_path.empty()) {
    std::printf("stencil-rig: journal %s\n", opened_path.c_str());
  }
  return true;
}

// What made this run, for the report and the journal.
void fill_provenance(app::RigOptions& o, int argc, char** argv, const tables::PartTables& part) {
  o.provenance.program = "stencil-rig";
  o.provenance.command_line.assign(argv, argv + argc);
  o.provenance.configuration = o.config_path;
  o.provenance.configuration_crc32 = o.config.file_crc32;
  o.provenance.tables = o.tables_path;
  o.provenance.tables_crc32 = part.header.crc32;
  o.provenance.triangle_count = part.header.triangle_count;
}

// The machine thread runs SCHED_FIFO below the cycle (which always preempts it) and above the
// records thread, which stays SCHED_OTHER with the journal's writes and fsyncs: the machine's
// updates keep their deadlines whatever the journal's disk does. Refused: it says so and runs on.
// Nothing turns the spindle on unattended: once homed, the operator types 'start' at the terminal,
// or (a service has no terminal) sends it over the controller's socket: `stencil-rig start`.
void wire_operator(RigJob& job, int machine_priority, app::TerminalCommands& terminal, display_link::DisplayLink* link) {
  job.interrupted = &interrupted;
  job.progress = [](const std::string& line) { std::fprintf(stderr, "stencil-rig: %s\n", line.c_str()); };
  job.operator_command = [&terminal] { return terminal.command_typed(); };
  job.prepare_machine_thread = [machine_priority] {
    const app::ThreadPriority got = app::run_this_thread_fifo(machine_priority, "the machine thread");
    if (!got.message.empty()) {
      std::fprintf(stderr, "stencil-rig: %s\n", got.message.c_str());
    }
  };
  job.confirm_spindle = [&terminal, link] {
    std::printf("stencil-rig: homed. Hold the handle still near the tool, then type 'start' and Enter to turn the "
                "spindle on (Ctrl-C ends)%s%s\n", link != nullptr ? ", or send it: stencil-rig start --socket " : "",
                link != nullptr ? link->socket_path().c_str() : "");
    std::fflush(stdout);
    using Answer = display_link::DisplayLink::StartAnswer;
    if (link != nullptr) {
      link->await_start();
    }
    bool closed_said = false;
    bool typed = false;
    while (!interrupted.load() && !typed && (link == nullptr || link->start_answer() == Answer::None)) {
      const app::TerminalCommands::Word word = terminal.next_word();
      typed = word == app::TerminalCommands::Word::Start;
      if (!typed && word == app::TerminalCommands::Word::Closed && !closed_said) {
        if (link == nullptr) {
          std::fprintf(stderr, "stencil-rig: no operator at the terminal (its input is closed): the spindle stays off\n");
          return false;
        }
        std::fprintf(stderr, "stencil-rig: no terminal: waiting for 'stencil-rig start' on %s\n", link->socket_path().c_str());
        closed_said = true;
      }
      if (!typed) {
        usleep(100'000);
      }
    }
    // Whatever the link took up to this moment decides with the terminal: a stop wins.
    const Answer answer = link != nullptr ? link->end_start_wait() : Answer::None;
    if (answer == Answer::Stop) {
      std::fprintf(stderr, "stencil-rig: stopped before the cut (a stop through the socket): the spindle stays off\n");
      return false;
    }
    return !interrupted.load() && (typed || answer == Answer::Start);
  };
}

void print_summary(const RigResult& result) {
  std::printf("stencil-rig: ran %.1f s, %llu cycles, %llu overruns, %llu periods skipped; wake-up p99 %.0f us, p99.9 %.0f us, "
              "max %.0f us; max force %.2f N; %llu machine updates, max lag %.3f mm; the model has %.1f mm3 removed\n"
              "stencil-rig: ended in the safe state: %s; faults: %s (%llu safe-state entries, %llu resets taken, %llu refused)\n",
              result.run_s, static_cast<unsigned long long>(result.cycles), static_cast<unsigned long long>(result.overruns),
              static_cast<unsigned long long>(result.missed_periods), result.wakeup_latency_us.p99,
              result.wakeup_latency_us.p999, result.wakeup_latency_us.max, result.max_force_n, static_cast<unsigned long long>(result.machine_updates),
              result.machine_max_lag_mm, result.model_removed_mm3, control::safe_reason_name(result.safe_state),
              result.first_fault == control::SafeReason::None ? "none" : control::safe_reason_name(result.first_fault),
              static_cast<unsigned long long>(result.safe_state_entries),
              static_cast<unsigned long long>(result.resets_accepted), static_cast<unsigned long long>(result.resets_refused));
}

// --gcode: the program from the journal just closed, as stencil-journal gcode writes it (the job's own
// touch-off is in the journal's record of the job). A failure is said; the cut stands in the journal.
bool write_gcode(const app::RigOptions& o, const board::sherline_suzuki::RigJob& job, const tables::PartTables& part,
                 const std::string& journal_path, std::string& error) {
  gcode::JournalExport settings;
  const motion::PlannerLimits limits = board::sherline_suzuki::planner_limits(job.facts);
  settings.path.path = limits.path;
  settings.path.update_s = limits.update_period_s;
  settings.path.home_world_mm = board::sherline_suzuki::rig_frames(job.offset, job.facts).home_world_mm;
  settings.program.safe_z_mm = settings.path.home_world_mm.z();
  settings.source_name = journal_path;
  settings.config_crc32 = o.config.file_crc32;
  gcode::ExportSummary summary;
  if (!gcode::export_journal_gcode(journal_path, part, settings, o.gcode_path, summary, error)) {
    return false;
  }
  std::printf("gcode: %s (%llu moves from %llu machine targets)\n", o.gcode_path.c_str(),
              static_cast<unsigned long long>(summary.moves), static_cast<unsigned long long>(summary.targets));
  return true;
}

// After the run: what it did, said at the terminal and in the report. The program's exit status.
int finish(const app::RigOptions& o, const RigResult& result, const char* link_error, bool journal_closed,
           const journal::JournalWriter& journal_writer) {
  print_summary(result);
  if (!result.error.empty()) {
    std::fprintf(stderr, "stencil-rig: %s\n", result.error.c_str());
  }
  if (!result.machine_stop_confirmed) {
    std::fprintf(stderr, "stencil-rig: WARNING: the mill's spindle and drivers could not be confirmed off (%s): switch the "
                 "mill's power off\n", link_error);
  }
  if (!journal_closed) {
    std::fprintf(stderr, "stencil-rig: %s\n", journal_writer.error().c_str());
  }
  std::string error;
  const std::string machine_error = result.machine_stall.empty() ? std::string(link_error) : result.machine_stall;
  if (!result.machine_stall.empty()) {
    std::fprintf(stderr, "stencil-rig: %s\n", result.machine_stall.c_str());
  }
  if (!o.report_path.empty() && !board::sherline_suzuki::write_rig_report(o.report_path, result, machine_error, o.provenance, error)) {
    return fail(kExitBadInput, error);
  }
  const bool asked = result.safe_state == control::SafeReason::Stopped && result.first_fault == control::SafeReason::None &&
                     result.error.empty() && journal_closed && result.machine_stop_confirmed;
  return asked ? 0 : kExitNotStarted;
}

// --commission: the mill alone (no haptic device), the machinist at the terminal. 0 when the file
// agrees with the mill, 3 when something does not (or it could not run).
int commission(const app::RigOptions& o) {
  struct sigaction action {};
  action.sa_handler = on_signal;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
    sigaction(signal_number, &action, nullptr);
  }
  board::sherline_suzuki::RigDevices devices;
  std::string error;
  if (!board::sherline_suzuki::open_rig_machine(o.config.facts, o.serial_path, devices, error)) {
    return fail(kExitNotStarted, error);
  }
  app::TerminalMachinist machinist(&interrupted);
  const board::sherline_suzuki::CommissioningResult result = board::sherline_suzuki::commission(
      o.config.facts, o.config.commissioning, *devices.link, devices.clock, machinist, &interrupted);
  std::printf("%s", board::sherline_suzuki::describe(result).c_str());
  return result.passed ? 0 : kExitNotStarted;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "stencil-rig: the haptic stencil controller on the Sherline + Suzuki rig. Checks the host's real-time\n"
      "readiness, loads the tables, opens the CY545's serial port and the haptic device's link, and says what\n"
      "is missing; then homes the mill and runs the 1 kHz cycle until SIGINT/SIGTERM/SIGHUP/SIGQUIT or --duration, and holds\n"
      "and stops the mill on the way out. While it runs, type 'stop' (the safe state: no force, the mill held and\n"
      "stopped), 'pause' (feed hold: the tool and the mill held where they are) and 'resume'. In a safe state type\n"
      "'reset' with the handle held still near the tool to feel the part again; the mill stays\n"
      "stopped (re-homing to resume the cut is not built yet).\n"
      "With no terminal (a service), the same come over the controller's socket (--display-socket):\n"
      "stencil-rig status|stop|reset|pause|resume|start [--socket PATH] from its own user or root.\n"
      "Each job writes its journal and report in a folder of its own (--out-dir), a --resume of it there too.\n"
      "Exit status: 0 stopped as asked with no fault, 2 bad input (a jobs folder that cannot be written\n"
      "among it), 3 could not start or a fault happened;\n"
      "a control command: 0 done, 1 refused by the controller, 3 no controller."};
  app.set_version_flag("--version", report::version_text("stencil-rig"));
  app::RigOptions o;
  app::add_rig_options(app, o);
  app::ControlOptions control;
  app::add_control_commands(app, control);
  app.require_subcommand(0, 1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), kExitBadInput);
  }
  if (control.chosen != nullptr) {
    return app::run_control(control.chosen->get_name(), control);
  }
  if (o.config_keys) {
    std::printf("%s", board::sherline_suzuki::describe_rig_config_keys().c_str());
    return 0;
  }
  RigJob job;
  std::string error;
  std::vector<unsigned char> bytes;
  tables::PartTables part{};
  if (!app::apply_rig_config(app, o, error)) {
    return fail(kExitBadInput, error);
  }
  if (o.commission) {
    return commission(o);
  }
  if (!app::check_rig_options(o, job.offset, job.stock, error) || !app::load_table_file(o.tables_path, bytes, part, error)) {
    return fail(kExitBadInput, error);
  }
  job.facts = o.config.facts;
  fill_provenance(o, argc, argv, part);
  const board::sherline_suzuki::TableFitJob fit{
      {job.offset.home_world_mm.x(), job.offset.home_world_mm.y(), job.offset.home_world_mm.z()},
      job.offset.tool_stick_out_mm, job.offset.reference_stick_out_mm};
  if (!board::sherline_suzuki::check_tables_fit(part.header, o.tables_path, job.facts, fit, error) ||
      !board::sherline_suzuki::check_stock_fit({job.stock.low_mm.x(), job.stock.low_mm.y(), job.stock.low_mm.z()},
                                               {job.stock.high_mm.x(), job.stock.high_mm.y(), job.stock.high_mm.z()},
                                               job.facts, fit, error)) {
    return fail(kExitBadInput, error);
  }
  std::printf("stencil-rig: tables %s: %u points, %u triangles\n", o.tables_path.c_str(), part.point_count(),
              part.triangle_count());
  const app::RtReadiness readiness = app::check_rt_readiness(bytes.size() + (64U << 20), o.priority);
  std::printf("real-time readiness:\n%s", app::describe(readiness).c_str());
  if (o.require_rt && (!readiness.preempt_rt || !readiness.can_sched_fifo)) {
    return fail(kExitNotStarted, "--require-rt: this host has no PREEMPT_RT kernel or may not use SCHED_FIFO");
  }
  // The link's command-to-motor delay, which the wall's feel weighs the force by.
  job.device_delay_s = o.haptic.rfind("can:", 0) == 0 ? hal::kCanCommandDelayS : hal::kPioCommandDelayS;
  board::sherline_suzuki::RigDevices devices;
  if (!board::sherline_suzuki::open_rig_devices(job.facts, o.serial_path, o.haptic, devices, [](const std::string& note) {
        std::printf("stencil-rig: %s\n", note.c_str());
      }, error)) {
    return fail(kExitNotStarted, error);
  }
  journal::JobJournalRequest request;
  journal::JournalWriter journal_writer;
  std::string journal_path;
  report::JobFolder folder;  // checked (made, written in) before anything moves
  if (!open_journal(o, part, job, folder, request, journal_writer, journal_path, error)) {
    return fail(kExitBadInput, error);
  }
  // Every signal that ends a session ends the job through the cycle's stop (spindle and drivers off):
  // a closed terminal (SIGHUP) or Ctrl-\ (SIGQUIT) as much as Ctrl-C. Nothing survives SIGKILL or a
  // power cut: the next start turns the outputs off first, and the rig needs its hardware watchdog.
  struct sigaction action {};
  action.sa_handler = on_signal;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
    sigaction(signal_number, &action, nullptr);
  }
  if (o.cpu >= 0 && !app::keep_off_cpu(o.cpu)) {
    std::fprintf(stderr, "stencil-rig: the other threads could not be kept off CPU %d\n", o.cpu);
  }
  app::Display display;
  if (!display.start(o.display, part, board::sherline_suzuki::rig_controller_config(job), "stencil-rig", error)) {
    if (!journal::undo_unrun_job_journal(request, journal_writer, journal_path)) {
      std::fprintf(stderr, "stencil-rig: %s: could not be cut back to the job it held\n", o.resume_path.c_str());
    }
    folder.abandon();
    return fail(kExitBadInput, error);
  }
  job.display = display.feed();
  job.part = &part;
  job.device = devices.device;
  job.machine = &devices.machine();
  job.machine_clock = &devices.clock;
  job.journal = journal_writer.is_open() ? &journal_writer : nullptr;
  job.resume_from = o.resume_path;
  job.resume_bytes = request.resume_bytes;
  job.duration_s = o.duration_s;
  app::TerminalCommands terminal;
  wire_operator(job, o.machine_priority, terminal, display.link());
  std::printf("stencil-rig: homing the mill (Ctrl-C stops it); the spindle starts only once you type 'start'\n");
  std::fflush(stdout);
  const RigResult result = board::sherline_suzuki::run_rig(
      job, app::realtime_runner({o.priority, o.cpu, o.require_rt},
                                [](const std::string& line) { std::fprintf(stderr, "stencil-rig: %s\n", line.c_str()); }));
  display.end(result.started ? "the job ended after " + std::to_string(result.cycles) + " cycles, in the safe state (" +
                                   control::safe_reason_name(result.safe_state) + ")"
                             : "the job did not start: " + result.error);
  display.stop();
  if (journal_writer.is_open() && result.started) {
    static_cast<void>(journal_writer.append_end(result.cycles, result.safe_state));  // an orderly end, not a kill
  }
  const bool journal_closed = !journal_writer.is_open() || journal_writer.close();
  if (!result.started) {
    if (!journal::undo_unrun_job_journal(request, journal_writer, journal_path)) {
      std::fprintf(stderr, "stencil-rig: %s: could not be cut back to the job it held\n", o.resume_path.c_str());
    }
    folder.abandon();
    const std::string link_error = devices.machine_error();
    return fail(kExitNotStarted, result.error + (link_error.empty() ? "" : ": " + link_error));
  }
  if (!o.gcode_path.empty() && journal_closed && !write_gcode(o, job, part, journal_path, error)) {
    std::fprintf(stderr, "stencil-rig: --gcode: %s\n", error.c_str());
  }
  return finish(o, result, devices.machine_error(), journal_closed, journal_writer);
}
