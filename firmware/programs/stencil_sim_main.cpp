// stencil-sim: the controller's cycle and machine side against the simulated device, the fake CY545
// on a pseudo-terminal and the simulated mill, on the baked-in sample part or a table file; reports
// gouges, coverage and loop timing.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
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
#include "firmware/programs/display_option.hpp"
#include "firmware/runtime/realtime_thread.hpp"
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

// The picture goes beside the report, as .svg.
std::string picture_path_of(const std::string& report_path) {
  return (report_path.size() > 5 && report_path.compare(report_path.size() - 5, 5, ".json") == 0
              ? report_path.substr(0, report_path.size() - 5)
              : report_path) +
         ".svg";
}

// --replay: every run the journal holds, in turn, each from the state the runs before it left.
int replay(const std::string& path, const tables::PartTables& part, board::sim::SimJob job, const std::string& report_path,
           const std::string& stock_csv_path, double pace) {
  journal::JobHistory history;
  std::string error;
  if (!journal::read_job_history(path, part.header.crc32, part.header.triangle_count, board::sim::frames(), {}, history,
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
    std::vector<control::JournalRecord> records;
    std::uint32_t in_run = 0;
    journal::JournalVisitor keep;
    keep.resume = [&](const journal::JournalResume&) { ++in_run; };
    keep.cycle = [&](const control::JournalRecord& r) {
      if (in_run == run) {
        records.push_back(r);
      }
    };
    const journal::JournalReadResult read = journal::read_journal_file(path, keep, history.good_bytes);
    if (!read.ok) {
      return bad_input("--replay: " + read.error);
    }
    job.replay = &records;
    job.resume_from = run == 0 ? "" : path;
    job.resume_bytes = run == 0 ? 0 : history.run_starts[run - 1];
    result = board::sim::run_fast(job);
    if (!result.started) {
      std::fprintf(stderr, "stencil-sim: %s\n", result.error.c_str());
      return kExitSafeState;
    }
    const bool reason_same = !control::is_device_reason(result.replay_recorded_reason) ||
                             result.safe_state == result.replay_recorded_reason;
    const bool same = result.replay_mismatches == 0 && result.replay_cycles == records.size() && reason_same;
    all_same = all_same && same;
    std::printf("replay run %u: %llu of %zu recorded cycles, %llu with a different virtual tool%s; recorded ending %s, "
                "replayed %s: %s\n",
                run, static_cast<unsigned long long>(result.replay_cycles), records.size(),
                static_cast<unsigned long long>(result.replay_mismatches),
                result.replay_first_mismatch >= 0 ? (" (the first at cycle " + std::to_string(result.replay_first_mismatch) + ")").c_str() : "",
                control::safe_reason_name(result.replay_recorded_reason), control::safe_reason_name(result.safe_state),
                same ? "the same" : "DIFFERENT");
  }
  std::printf("%s", board::sim::summary(result).c_str());
  const std::string picture_path = picture_path_of(report_path);
  if (!board::sim::write_report_json(report_path, result, error) || !board::sim::write_picture_svg(picture_path, result, error) ||
      (!stock_csv_path.empty() && !board::sim::write_stock_csv(stock_csv_path, result, error))) {
    return bad_input(error);
  }
  std::printf("report: %s\npicture: %s\n", report_path.c_str(), picture_path.c_str());
  std::printf("replay: %s\n", all_same ? "every run replayed as recorded" : "the replay differs from the record");
  return all_same ? kExitDone : kExitSafeState;
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
      "material; reports gouges, coverage and loop timing. Exit status: 0 done, 2 bad input, 3 ended in a\n"
      "safe state."};
  std::string tables_path;
  std::string operator_path;
  std::string pattern_name = "raster";
  std::uint64_t seed = 1;
  double duration_s = 0.0;
  bool fast = false;
  std::string report_path = "stencil-sim-report.json";
  bool until_complete = false;
  std::string stock_text;
  std::string trace_path;
  std::string transport = "direct";
  app.add_option("--tables", tables_path, "the part's .stbl (default: the baked-in hex prism, ball end mill d = 3 mm)");
  app.add_option("--operator", operator_path, "the operator's script: CSV rows t_s,x_mm,y_mm,z_mm[,a_rad,b_rad] in device space");
  app.add_option("--pattern", pattern_name, "the operator's pattern when there is no --operator file")
      ->check(CLI::IsMember({"raster", "plunge", "thinwall", "random"}))
      ->capture_default_str();
  app.add_option("--seed", seed, "the random pattern's seed")->capture_default_str();
  int moves = 200;
  app.add_option("--moves", moves, "the random pattern's number of moves (200 take about 40 simulated minutes)")
      ->check(CLI::Range(1, 1'000'000))
      ->capture_default_str();
  app.add_option("--duration", duration_s, "simulated seconds to run (default: the script's length)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--fast", fast, "virtual clock, as fast as the machine allows, deterministic");
  double speed = 0.0;
  int priority = 80;
  int cpu = -1;
  bool require_rt = false;
  app.add_option("--speed", speed,
                 "N x real time. 1: the cycle on a SCHED_FIFO thread at 1 kHz and the machine and the fake CY545 on "
                 "threads of their own, on the wall clock (what make latency measures); any other N: the --fast "
                 "virtual clock held to N simulated seconds per second, deterministic, so a person can watch")
      ->check(CLI::Range(1e-3, 1e6));
  app.add_option("--priority", priority, "real time: the cycle thread's SCHED_FIFO priority")
      ->check(CLI::Range(1, 99))
      ->capture_default_str();
  app.add_option("--cpu", cpu, "real time: pin the cycle thread to this CPU")->check(CLI::NonNegativeNumber);
  app.add_flag("--require-rt", require_rt, "real time: refuse to run without SCHED_FIFO and locked memory");
  app.add_option("--report", report_path, "the JSON report; the picture goes beside it as .svg")->capture_default_str();
  app.add_flag("--until-complete", until_complete,
               "end once every reachable triangle is touched and the mill has caught up with the virtual tool");
  app.add_option("--stock", stock_text, "the stock block X0,Y0,Z0,X1,Y1,Z1 in world mm (default: the part's box grown by 2 mm)");
  std::string inject_text;
  board::sim::FaultInjection job_fault;
  app.add_option("--inject", inject_text,
                 "KIND@S: inject one fault S simulated seconds into the job (--fast or --speed N other than 1); KIND is " +
                     board::sim::fault_kind_names(board::sim::FaultKindList::Sentence) +
                     "; the report's fault section says when the safe state, zero force and the stopped mill followed");
  std::string journal_path;
  bool no_journal = false;
  std::string resume_path;
  std::string stock_csv_path;
  app.add_option("--journal", journal_path,
                 "record the job here: every cycle's device sample, virtual tool and force, every machine command "
                 "(written before it is sent) and every safe-state event, with a CRC-32 each, synced to the disk every "
                 "second and at once on a safe state (default: stencil-sim-YYYYMMDD-HHMMSS.journal in the current "
                 "folder, named after the start time; about 400 MB per simulated hour)");
  app.add_flag("--no-journal", no_journal, "record no journal (the job cannot be resumed)");
  app.add_option("--resume", resume_path,
                 "carry on the job this journal recorded (after a crash, a kill or a safe state), given the same "
                 "--tables, --pattern, --seed, --operator and --stock: the touched set and the stock as machined are "
                 "rebuilt from it, the machine homes again, the simulated operator goes back across at home's height "
                 "and down to where the cut stopped and carries on with its script; the journal carries on in the "
                 "same file and the report covers the whole job (--duration is then the whole job's)");
  std::string replay_path;
  app.add_option("--replay", replay_path,
                 "re-run the job this journal recorded, deterministically, on the virtual clock: each cycle reads "
                 "exactly what the recorded cycle read from the device (every run of a resumed job in turn, each "
                 "from the state the runs before it left); says whether every cycle's virtual tool came out bit for "
                 "bit as recorded (exit 0) or where it first differed (exit 3). Writes the report and no journal");
  app.add_option("--stock-csv", stock_csv_path,
                 "write the machined stock's heights here at the end: one row of the Z-map per line (y rising), "
                 "mm, cells of 0.05 mm from the stock's low corner");
  std::string device_log_path;
  app.add_option("--device-process", device_log_path,
                 "LOG: with --haptic-transport pio only: the simulated device and the operator's hand run in a process of "
                 "their own (on the virtual clock in lockstep with the cycle, so the job is the same job; in real time "
                 "on the wall clock), so that if this one dies, even by SIGKILL, the device's own host watchdog zeroes "
                 "the force; the device writes to LOG how long that took");
  app.add_option("--trace", trace_path, "write the simulated mill's true path corners to this CSV (t_s,x_mm,y_mm,z_mm)");
  app.add_option("--haptic-transport", transport,
                 "how the cycle reaches the simulated device: in process, or through the real PIO shared-memory or "
                 "SocketCAN code over a memfd or a socketpair")
      ->check(CLI::IsMember({"direct", "pio", "can"}))
      ->capture_default_str();
  app::DisplayOptions display_options;
  app::add_display_options(app, display_options);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), kExitBadInput);
  }
  {
    std::string display_error;
    if (!app::check_display_options(display_options, display_error)) {
      return bad_input(display_error);
    }
  }

  if ((fast || (speed > 0.0 && speed != 1.0)) &&
      (app.count("--priority") + app.count("--cpu") + app.count("--require-rt")) > 0) {
    return bad_input("--priority, --cpu and --require-rt are for the real-time threads of --speed 1 only");
  }
  if (!inject_text.empty()) {
    const std::size_t at = inject_text.find('@');
    double at_s = 0.0;
    if (at == std::string::npos || !board::sim::parse_fault_kind(inject_text.substr(0, at), job_fault.kind) ||
        !sim::parse_finite_field(inject_text.substr(at + 1), at_s) || at_s < 0.0) {
      return bad_input("--inject " + inject_text + ": expected KIND@SECONDS, KIND one of " +
                       board::sim::fault_kind_names(board::sim::FaultKindList::Plain));
    }
    job_fault.at_s = at_s;
    if (job_fault.kind == board::sim::FaultKind::CanBadFrames && transport != "can") {
      return bad_input("--inject can-bad-frames: the bad frames are CAN frames (--haptic-transport can)");
    }
    if (speed == 1.0) {
      return bad_input("--inject: faults are injected on the virtual clock (--fast or --speed N other than 1)");
    }
  }
  if (!replay_path.empty()) {
    if (!resume_path.empty() || !journal_path.empty() || !inject_text.empty() || app.count("--device-process") > 0 ||
        speed == 1.0 || display_options.requested()) {
      return bad_input("--replay runs the recorded job on the virtual clock by itself: no --resume, --journal, --inject, "
                       "--device-process, --hmi or --speed 1 with it");
    }
    fast = fast || speed == 0.0;
    no_journal = true;
  }
  if (!resume_path.empty() && (!journal_path.empty() || no_journal)) {
    return bad_input("--resume carries on in the journal it resumes: no --journal or --no-journal with it");
  }
  if (no_journal && !journal_path.empty()) {
    return bad_input("--journal and --no-journal: choose one");
  }
  if (!device_log_path.empty() && (transport != "pio" || !inject_text.empty())) {
    return bad_input("--device-process: the device runs in its own process only with --haptic-transport pio and no --inject");
  }
  if (fast == (speed > 0.0)) {
    return bad_input(fast ? "--fast and --speed: choose one" : "pass --fast (virtual time) or --speed N (N x real time)");
  }

  // The part: a table file read into memory, or the baked-in section used in place.
  std::vector<unsigned char> file_bytes;
  tables::PartTables part{};
  if (tables_path.empty()) {
    const tables::TableLoadResult loaded =
        tables::load_tables({reinterpret_cast<const std::byte*>(stencil_table_hex_prism), stencil_table_hex_prism_size}, part);
    if (!loaded.ok) {
      return bad_input(std::string("the baked-in table does not load: ") + loaded.field);
    }
  } else {
    std::ifstream in(tables_path, std::ios::binary);
    if (!in) {
      return bad_input(tables_path + ": cannot be read");
    }
    file_bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    const tables::TableLoadResult loaded =
        tables::load_tables({reinterpret_cast<const std::byte*>(file_bytes.data()), file_bytes.size()}, part);
    if (!loaded.ok) {
      return bad_input(tables_path + ": not a valid table: " + loaded.field);
    }
  }

  board::sim::SimJob job;
  job.part = &part;
  job.stock = board::sim::default_stock(part);
  std::string error;
  if (!stock_text.empty() && !parse_stock(stock_text, part, job.stock, error)) {
    return bad_input(error);
  }
  const Eigen::Vector3d home(board::sim::kHomeWorldMm[0], board::sim::kHomeWorldMm[1], board::sim::kHomeWorldMm[2]);
  if (!operator_path.empty()) {
    if (!sim::read_operator_csv(operator_path, job.script, error)) {
      return bad_input(error);
    }
  } else {
    const sim::Pattern pattern = pattern_name == "raster"  ? sim::Pattern::Raster
                                 : pattern_name == "plunge" ? sim::Pattern::Plunge
                                 : pattern_name == "thinwall" ? sim::Pattern::Thinwall
                                                              : sim::Pattern::Random;
    job.script = sim::make_pattern(pattern, job.stock, home, board::sim::kOperatorSpeedMmPerS,
                                   board::sim::kDeviceMmPerWorldMm, seed, board::sim::touch_tip_of(part, job.stock), moves);
  }
  // What makes the job the same job when it is resumed: recorded at its start, checked on resume.
  char numbers[200];
  std::snprintf(numbers, sizeof numbers, " seed=%llu moves=%d stock=%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                static_cast<unsigned long long>(seed), moves, job.stock.low_mm.x(), job.stock.low_mm.y(),
                job.stock.low_mm.z(), job.stock.high_mm.x(), job.stock.high_mm.y(), job.stock.high_mm.z());
  const std::string job_text = "tables=" + (tables_path.empty() ? std::string("(baked-in hex prism)") : tables_path) +
                               " operator=" + (operator_path.empty() ? std::string("-") : operator_path) +
                               " pattern=" + (operator_path.empty() ? pattern_name : std::string("-")) + numbers;
  if (job_text.size() > 1024) {
    return bad_input("--tables and --operator: paths too long to record in the journal (" + std::to_string(job_text.size()) +
                     " bytes of the job; at most 1024)");
  }
  if (!replay_path.empty()) {
    return replay(replay_path, part, job, report_path, stock_csv_path, fast ? 0.0 : speed);
  }
  journal::JobHistory history;
  journal::JournalResume resume;
  if (!resume_path.empty()) {
    // A first look at the journal: is it this job, and where did it stop? The rebuild is the job's.
    if (!journal::read_job_history(resume_path, part.header.crc32, part.header.triangle_count,
                                   board::sim::frames(), {}, history, error)) {
      return bad_input("--resume: " + error);
    }
    if (history.start.job != job_text) {
      return bad_input("--resume " + resume_path + ": recorded for another job (" + history.start.job +
                       "); this one is " + job_text + ": resume with the recorded job's options");
    }
    if (!history.tail.empty()) {
      std::printf("resume: %s: ignoring its torn tail (%s)\n", resume_path.c_str(), history.tail.c_str());
    }
    // Where the cut stopped: the mill's last target (the stock is cut there), else the virtual tool.
    const Eigen::Vector3d rejoin = history.machine_commands > 0 ? history.last_commanded_tip_mm : history.last_virtual_tip_mm;
    double approach_s = 0.0;
    job.script = sim::carry_on(job.script, history.script_s, home, rejoin, board::sim::kOperatorSpeedMmPerS,
                               board::sim::kDeviceMmPerWorldMm, approach_s);
    resume.segment = history.segments;
    resume.script_s = history.script_s;
    resume.approach_s = approach_s;
    if (duration_s > 0.0) {
      duration_s = approach_s + std::max(0.0, duration_s - history.script_s);
    }
    std::printf("resume: %s: %u run(s), %llu cycles, %zu safe state(s), %llu machine commands; the script carries on "
                "from %.3f s after %.1f s back to (%.3f, %.3f, %.3f) mm\n",
                resume_path.c_str(), history.segments, static_cast<unsigned long long>(history.cycles),
                history.faults.size(), static_cast<unsigned long long>(history.machine_commands), history.script_s,
                approach_s, rejoin.x(), rejoin.y(), rejoin.z());
    job.resume_from = resume_path;
    job.resume_bytes = history.good_bytes;
  }
  job.transport = transport == "pio"   ? board::sim::HapticTransport::Pio
                  : transport == "can" ? board::sim::HapticTransport::Can
                                       : board::sim::HapticTransport::Direct;
  job.duration_s = duration_s;
  job.fault = job_fault;
  job.until_complete = until_complete;
  std::FILE* trace = nullptr;
  if (!trace_path.empty()) {
    trace = std::fopen(trace_path.c_str(), "w");
    if (trace == nullptr) {
      return bad_input(trace_path + ": cannot be written");
    }
    std::fprintf(trace, "t_s,x_mm,y_mm,z_mm\n");
    job.trace = trace;
  }
  if (isatty(STDERR_FILENO) != 0) {
    job.progress = [&](double t_s, double coverage) {
      std::fprintf(stderr, "\rstencil-sim: %.0f of %.0f simulated s, coverage %.1f %%   ", t_s, job.script.duration_s(),
                   100.0 * coverage);
    };
  }
  std::printf("stencil-sim: %s, %s pattern over the stock [%.1f,%.1f]x[%.1f,%.1f]x[%.1f,%.1f] mm, %.0f simulated s\n",
              tables_path.empty() ? "the baked-in hex prism" : tables_path.c_str(),
              operator_path.empty() ? pattern_name.c_str() : operator_path.c_str(), job.stock.low_mm.x(),
              job.stock.high_mm.x(), job.stock.low_mm.y(), job.stock.high_mm.y(), job.stock.low_mm.z(),
              job.stock.high_mm.z(), job.script.duration_s());
  std::fflush(stdout);

  const std::string picture_path = picture_path_of(report_path);
  // The outputs can be written: found out now, not after the whole simulated job (every input has
  // been checked by now, so bad input leaves no report behind).
  for (const std::string& path : {report_path, picture_path}) {
    const bool existed = access(path.c_str(), F_OK) == 0;
    std::ofstream probe(path, std::ios::app);
    if (!probe) {
      return bad_input(path + ": cannot be written");
    }
    probe.close();
    if (!existed) {
      std::remove(path.c_str());  // made only to find out: a refused run leaves nothing behind
    }
  }
  std::FILE* device_log = nullptr;
  if (!device_log_path.empty()) {
    device_log = std::fopen(device_log_path.c_str(), "w");
    if (device_log == nullptr) {
      return bad_input(device_log_path + ": cannot be written");
    }
    job.device_process_log = device_log;
  }
  journal::JournalWriter journal_writer;
  const auto now = std::chrono::system_clock::now();
  const std::int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
  if (!resume_path.empty()) {
    resume.unix_time_ns = now_ns;
    resume.program = "stencil-sim";
    if (!journal_writer.open_to_resume(resume_path, history.good_bytes, resume)) {
      return bad_input(journal_writer.error());
    }
    journal_path = resume_path;
    job.journal = &journal_writer;
    std::printf("journal: %s (carried on)\n", journal_path.c_str());
    std::fflush(stdout);
  } else if (!no_journal) {
    if (journal_path.empty()) {
      const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
      std::tm local{};
      localtime_r(&seconds, &local);
      char name[64];
      std::strftime(name, sizeof name, "stencil-sim-%Y%m%d-%H%M%S.journal", &local);
      journal_path = name;
    }
    journal::JournalStart start;
    start.tables_crc32 = part.header.crc32;
    start.triangle_count = part.header.triangle_count;
    start.unix_time_ns = now_ns;
    start.program = "stencil-sim";
    start.job = job_text;
    if (!journal_writer.open(journal_path, start)) {
      return bad_input(journal_writer.error());
    }
    job.journal = &journal_writer;
    std::printf("journal: %s\n", journal_path.c_str());
    std::fflush(stdout);
  }
  // The display, before the job: a page opened now sees the job from its start.
  app::Display display;
  if (!display.start(display_options, part, board::sim::controller_config(!fast && speed == 1.0), error)) {
    return bad_input(error);
  }
  job.display = display.feed();
  job.interrupted = &interrupted;
  board::sim::SimResult result;
  if (fast || speed != 1.0) {
    job.pace = fast ? 0.0 : speed;
    // Every machine update is a few round trips over the pty, each of which wakes a CPU: kept out
    // of deep idle states for the run, the demo job takes about a third less wall time here.
    const app::CpuLatencyHold latency_hold;
    result = board::sim::run_fast(job);
  } else {
    const app::RealtimeOptions options{priority, cpu, require_rt};
    // The machine, fake CY545 and records threads start after this and inherit it: the cycle's
    // CPU is left to the cycle.
    if (cpu >= 0 && !app::keep_off_cpu(cpu)) {
      std::fprintf(stderr, "stencil-sim: the other threads could not be kept off CPU %d; they share it with the cycle\n", cpu);
    }
    result = board::sim::run_realtime(
        job, [&](hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
                 const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>& cycle, std::string& refused) {
          const app::RealtimeSetup setup = app::run_periodic(options, period_ns, stop, cycle, [](const std::string& line) {
            std::fprintf(stderr, "stencil-sim: %s\n", line.c_str());
          });
          refused = setup.refused.empty() ? "" : "--require-rt: " + setup.refused;
          return setup.refused.empty();
        });
  }
  if (job.progress) {
    std::fprintf(stderr, "\n");
  }
  display.stop();
  if (trace != nullptr) {
    std::fclose(trace);
  }
  if (device_log != nullptr) {
    std::fclose(device_log);
  }
  if (!result.started) {
    // Nothing was run: what this run created for its outputs goes too, and a resumed journal goes
    // back to what it held (no Resume record of a run that never ran).
    static_cast<void>(journal_writer.close());
    if (!journal_path.empty() && resume_path.empty()) {
      std::remove(journal_path.c_str());
    } else if (!resume_path.empty() && ::truncate(resume_path.c_str(), static_cast<off_t>(history.good_bytes)) != 0) {
      std::fprintf(stderr, "stencil-sim: %s: could not be cut back to the job it held\n", resume_path.c_str());
    }
    if (!trace_path.empty()) {
      std::remove(trace_path.c_str());
    }
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
    result.journal_error = closed ? "" : journal_writer.error();
  }
  std::printf("%s", board::sim::summary(result).c_str());
  if (!board::sim::write_report_json(report_path, result, error) ||
      !board::sim::write_picture_svg(picture_path, result, error)) {
    return bad_input(error);
  }
  if (!stock_csv_path.empty() && !board::sim::write_stock_csv(stock_csv_path, result, error)) {
    return bad_input(error);
  }
  std::printf("report: %s\npicture: %s\n", report_path.c_str(), picture_path.c_str());
  // A journal that lost records is not a job done, even if the cut itself ended well.
  return result.safe_state == control::SafeReason::None && result.journal_error.empty() ? kExitDone : kExitSafeState;
}
