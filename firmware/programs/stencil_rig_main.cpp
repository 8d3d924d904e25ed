// stencil-rig: the controller on the real rig (board sherline_suzuki): the haptic device over the
// PIO shared-memory card or SocketCAN, the mill's CY545 over RS-232. It starts by checking
// everything it can (the host's real-time readiness, the tables, the serial port, the haptic link)
// and says plainly what is missing, then homes the mill and runs the cycle until SIGINT, SIGTERM, SIGHUP or SIGQUIT,
// --duration or a safe state, and stops the machine on the way out.
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>
#include <cmath>
#include <memory>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/programs/display_option.hpp"
#include "firmware/runtime/realtime_thread.hpp"
#include "firmware/runtime/rt_readiness.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "hal/socketcan/can_frame_layout.hpp"
#include "hal/socketcan/can_interface_bitrate.hpp"
#include "hal/socketcan/fd_can_channel.hpp"

namespace {

using namespace stencil;

constexpr int kExitBadInput = 2;
constexpr int kExitNotStarted = 3;

int fail(int status, const std::string& message) {
  std::fprintf(stderr, "stencil-rig: %s\n", message.c_str());
  return status;
}

std::atomic<bool> interrupted{false};
void on_signal(int) { interrupted.store(true); }

// The operator's lines at the terminal, read without waiting (from the records thread only): true
// once a line says "reset". Anything else typed is answered with what is understood.
class TerminalCommands {
 public:
  enum class Word { None, Start, Closed };
  // Before the cut: whether 'start' was typed (anything else is answered), or the input closed.
  Word next_word() {
    read_pending();
    for (std::size_t end = pending_.find('\n'); end != std::string::npos; end = pending_.find('\n')) {
      std::string line = pending_.substr(0, end);
      pending_.erase(0, end + 1);
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) {
        line.pop_back();
      }
      if (line == "start") {
        return Word::Start;
      }
      std::fprintf(stderr, "stencil-rig: '%s' is not 'start': type 'start' to turn the spindle on, or Ctrl-C\n", line.c_str());
    }
    return closed_ ? Word::Closed : Word::None;
  }

  bool reset_typed() {
    if (closed_) {
      return false;
    }
    read_pending();
    bool reset = false;
    for (std::size_t end = pending_.find('\n'); end != std::string::npos; end = pending_.find('\n')) {
      std::string line = pending_.substr(0, end);
      pending_.erase(0, end + 1);
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) {
        line.pop_back();
      }
      if (line == "reset") {
        reset = true;
      } else if (!line.empty()) {
        std::fprintf(stderr, "stencil-rig: '%s' is not a command: type 'reset' (in the safe state) or Ctrl-C to end\n",
                     line.c_str());
      }
    }
    if (pending_.size() > 1024) {
      pending_.clear();  // a line that long is not a command
    }
    return reset;
  }

 private:
  void read_pending() {
    pollfd in{STDIN_FILENO, POLLIN, 0};
    while (!closed_ && poll(&in, 1, 0) > 0 && (in.revents & (POLLIN | POLLHUP)) != 0) {
      char bytes[256];
      const ssize_t n = ::read(STDIN_FILENO, bytes, sizeof bytes);
      if (n <= 0) {
        closed_ = true;  // end of input (not a terminal, or closed): nothing more to read
        break;
      }
      pending_.append(bytes, static_cast<std::size_t>(n));
    }
  }

  std::string pending_;
  bool closed_ = false;
};

// "X,Y,Z" (or six numbers for a block) as finite numbers, all of each field: false otherwise.
bool parse_numbers(const std::string& text, std::vector<double>& out, std::size_t count) {
  out.clear();
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string field = text.substr(at, comma - at);
    char* end = nullptr;
    const double value = std::strtod(field.c_str(), &end);
    if (field.empty() || end != field.c_str() + field.size() || !std::isfinite(value)) {
      return false;
    }
    out.push_back(value);
    at = comma + 1;
  }
  return out.size() == count;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "stencil-rig: the haptic stencil controller on the Sherline + Suzuki rig. Checks the host's real-time\n"
      "readiness, loads the tables, opens the CY545's serial port and the haptic device's link, and says what\n"
      "is missing; then homes the mill and runs the 1 kHz cycle until SIGINT/SIGTERM/SIGHUP/SIGQUIT or --duration, and holds\n"
      "and stops the mill on the way out. In a fault's safe state (no force, the mill held and\n"
      "stopped) type 'reset' with the handle held still near the tool to feel the part again; the mill stays\n"
      "stopped (re-homing to resume the cut is not built yet).\n"
      "Exit status: 0 stopped as asked with no fault, 2 bad input, 3 could not start or a fault happened."};
  std::string tables_path;
  std::string serial_path;
  std::string haptic;
  bool require_rt = false;
  int priority = 80;
  app.add_option("--tables", tables_path, "the part's .stbl")->required();
  app.add_option("--serial", serial_path, "the CY545's serial port, e.g. /dev/ttyS0")->required();
  app.add_option("--haptic", haptic, "the haptic link: pio:/dev/uioN or can:IFACE")->required();
  app.add_flag("--require-rt", require_rt, "refuse to run without PREEMPT_RT and SCHED_FIFO");
  app.add_option("--priority", priority, "the cycle thread's SCHED_FIFO priority")->check(CLI::Range(1, 99))->capture_default_str();
  int cpu = -1;
  app.add_option("--cpu", cpu, "pin the cycle thread to this CPU (the other threads keep off it)")->check(CLI::NonNegativeNumber);
  namespace rig = board::sherline_suzuki;
  char home_text[64];
  std::snprintf(home_text, sizeof home_text, "%g,%g,%g", rig::kHomeWorldMm[0], rig::kHomeWorldMm[1], rig::kHomeWorldMm[2]);
  std::string offset_text = home_text;  // the machine's home before any touch-off
  app.add_option("--work-offset", offset_text,
                 "X,Y,Z: where the tool tip is in the part's coordinates (mm) with the machine at home, from the touch-off")
      ->capture_default_str();
  double stick_out = 0.0, reference_stick_out = 0.0;
  app.add_option("--tool-stick-out", stick_out, "the tool's stick-out below the holder (mm); with --reference-stick-out")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--reference-stick-out", reference_stick_out,
                 "the stick-out of the tool the touch-off was made with (mm): a longer tool puts the tip lower")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  std::string stock_text;
  app.add_option("--stock", stock_text, "the stock block X0,Y0,Z0,X1,Y1,Z1 in world mm (default: the whole workspace)");
  std::string report_path;
  app.add_option("--report", report_path, "write the run's figures here as JSON");
  std::string journal_path;
  app.add_option("--journal", journal_path,
                 "record the job here: every cycle's sample, virtual tool and force, every machine command (written "
                 "before it is sent), every safe-state event (default: stencil-rig-YYYYMMDD-HHMMSS.journal in the "
                 "current folder, named after the start time)");
  bool no_journal = false;
  app.add_flag("--no-journal", no_journal, "record no journal (the job cannot be resumed)");
  std::string resume_path;
  app.add_option("--resume", resume_path,
                 "carry on the job this journal recorded (after a crash, a kill or a safe state), with the same --tables, "
                 "--work-offset, stick-outs and --stock: the touched set and the model of the machined stock are rebuilt "
                 "from it, the mill homes again (Z first, out of the stock) and the cut carries on from wherever the "
                 "operator takes the handle; the journal carries on in the same file and the report covers the whole job");
  double duration_s = 0.0;
  app.add_option("--duration", duration_s, "stop after this many seconds (default: until SIGINT, SIGTERM, SIGHUP or SIGQUIT)")
      ->check(CLI::NonNegativeNumber);
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
      return fail(kExitBadInput, display_error);
    }
  }

  // (CLI11's range check lets a NaN through: every comparison with it is false.)
  if (!std::isfinite(stick_out) || !std::isfinite(reference_stick_out)) {
    return fail(kExitBadInput, "--tool-stick-out and --reference-stick-out: expected a length in mm from 0 to 100");
  }
  std::vector<double> numbers;
  if (!parse_numbers(offset_text, numbers, 3)) {
    return fail(kExitBadInput, "--work-offset " + offset_text + ": expected X,Y,Z in mm");
  }
  board::sherline_suzuki::WorkOffset offset;
  offset.home_world_mm = Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
  offset.tool_stick_out_mm = stick_out;
  offset.reference_stick_out_mm = reference_stick_out;
  control::StockBlock stock{{0.0, 0.0, 0.0}, {rig::kRig.workspace_mm[0], rig::kRig.workspace_mm[1], rig::kRig.workspace_mm[2]}};
  if (!stock_text.empty()) {
    bool inside = parse_numbers(stock_text, numbers, 6);
    for (int axis = 0; inside && axis < 3; ++axis) {
      const auto a = static_cast<std::size_t>(axis);
      inside = numbers[a] >= 0.0 && numbers[a] < numbers[a + 3] && numbers[a + 3] <= rig::kRig.workspace_mm[a];
    }
    if (!inside) {
      char workspace_text[96];
      std::snprintf(workspace_text, sizeof workspace_text, "[0,%g]x[0,%g]x[0,%g]", rig::kRig.workspace_mm[0],
                    rig::kRig.workspace_mm[1], rig::kRig.workspace_mm[2]);
      return fail(kExitBadInput, "--stock " + stock_text +
                                     ": expected X0,Y0,Z0,X1,Y1,Z1 in mm with each high above its low, inside the workspace " +
                                     workspace_text);
    }
    stock = {{numbers[0], numbers[1], numbers[2]}, {numbers[3], numbers[4], numbers[5]}};
  }
  if (!report_path.empty()) {  // found out now, not after the job
    const bool existed = access(report_path.c_str(), F_OK) == 0;
    std::ofstream probe(report_path, std::ios::app);
    if (!probe) {
      return fail(kExitBadInput, report_path + ": cannot be written");
    }
    probe.close();
    if (!existed) {
      std::remove(report_path.c_str());
    }
  }
  const bool pio = haptic.rfind("pio:", 0) == 0;
  const bool can = haptic.rfind("can:", 0) == 0;
  if ((!pio && !can) || haptic.size() <= 4) {
    return fail(kExitBadInput, "--haptic " + haptic + ": expected pio:/dev/uioN or can:IFACE");
  }

  std::vector<unsigned char> bytes;
  {
    std::ifstream in(tables_path, std::ios::binary);
    if (!in) {
      return fail(kExitBadInput, tables_path + ": cannot be read");
    }
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  tables::PartTables part{};
  const tables::TableLoadResult loaded = tables::load_tables({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, part);
  if (!loaded.ok) {
    return fail(kExitBadInput, tables_path + ": not a valid table: " + loaded.field);
  }
  std::printf("stencil-rig: tables %s: %u points, %u triangles\n", tables_path.c_str(), part.point_count(),
              part.triangle_count());

  const app::RtReadiness readiness = app::check_rt_readiness(bytes.size() + (64U << 20), priority);
  std::printf("real-time readiness:\n%s", app::describe(readiness).c_str());
  if (require_rt && (!readiness.preempt_rt || !readiness.can_sched_fifo)) {
    return fail(kExitNotStarted, "--require-rt: this host has no PREEMPT_RT kernel or may not use SCHED_FIFO");
  }

  hal::cy545::SerialPort port;
  char port_error[256] = {};
  if (!port.open(serial_path.c_str(), rig::kRig.serial_baud, port_error)) {
    return fail(kExitNotStarted, std::string("the mill's CY545: ") + port_error);
  }
  std::string error;
  std::unique_ptr<hal::pio_shared_memory::SharedWindowMapping> window;
  std::unique_ptr<hal::socketcan::FdCanChannel> channel;
  std::unique_ptr<hal::pio_shared_memory::PioHapticDevice> pio_device;
  std::unique_ptr<hal::socketcan::SocketCanHapticDevice> can_device;
  hal::HapticDevice* device = nullptr;
  if (pio) {
    const std::string path = haptic.substr(4);
    window = hal::pio_shared_memory::SharedWindowMapping::open(path, 0, true, error);
    if (window == nullptr) {
      return fail(kExitNotStarted, "the haptic device's PIO window: " + error);
    }
    pio_device = std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&window->window(), board::sherline_suzuki::kDeviceRange);
    device = pio_device.get();
  } else {
    const std::string interface = haptic.substr(4);
    const canid_t ids[] = {hal::socketcan::kPoseAId, hal::socketcan::kPoseBId, hal::socketcan::kStatusId};
    const int fd = hal::socketcan::open_can_raw_socket(interface, ids, 3, error);
    if (fd < 0) {
      return fail(kExitNotStarted, "the haptic device's CAN link: " + error);
    }
    channel = std::make_unique<hal::socketcan::FdCanChannel>(fd);
    // A bus too slow for a period's frames is refused here, not found out as late poses in the cycle.
    std::string bitrate_note;
    if (!hal::socketcan::check_can_bitrate(interface, bitrate_note, error)) {
      return fail(kExitNotStarted, "the haptic device's CAN link: " + error);
    }
    std::printf("stencil-rig: %s\n", bitrate_note.c_str());
    can_device = std::make_unique<hal::socketcan::SocketCanHapticDevice>(channel.get(), board::sherline_suzuki::kDeviceRange);
    device = can_device.get();
  }

  // What makes the job the same job when it is resumed: recorded at its start, checked on resume.
  char job_text[300];
  std::snprintf(job_text, sizeof job_text,
                "work-offset=%.6f,%.6f,%.6f tool-stick-out=%.6f reference-stick-out=%.6f stock=%.6f,%.6f,%.6f,%.6f,%.6f,%.6f",
                offset.home_world_mm.x(), offset.home_world_mm.y(), offset.home_world_mm.z(), offset.tool_stick_out_mm,
                offset.reference_stick_out_mm, stock.low_mm.x(), stock.low_mm.y(), stock.low_mm.z(), stock.high_mm.x(),
                stock.high_mm.y(), stock.high_mm.z());
  journal::JournalWriter journal_writer;
  journal::JobHistory history;
  const auto now = std::chrono::system_clock::now();
  const std::int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
  if (!resume_path.empty()) {
    if (!journal_path.empty() || no_journal) {
      return fail(kExitBadInput, "--resume carries on in the journal it resumes: no --journal or --no-journal with it");
    }
    std::string history_error;
    if (!journal::read_job_history(resume_path, part.header.crc32, part.header.triangle_count,
                                   board::sherline_suzuki::rig_frames(offset), {}, history, history_error)) {
      return fail(kExitBadInput, "--resume: " + history_error);
    }
    if (history.start.job != job_text) {
      return fail(kExitBadInput, "--resume " + resume_path + ": recorded for another job (" + history.start.job +
                                     "); this one is " + job_text + ": resume with the recorded job's options");
    }
    journal::JournalResume resume;
    resume.segment = history.segments;
    resume.unix_time_ns = now_ns;
    resume.program = "stencil-rig";
    if (!journal_writer.open_to_resume(resume_path, history.good_bytes, resume)) {
      return fail(kExitBadInput, journal_writer.error());
    }
    std::printf("stencil-rig: resuming %s: %u run(s), %llu cycles, %zu safe state(s), %llu machine commands%s\n",
                resume_path.c_str(), history.segments, static_cast<unsigned long long>(history.cycles), history.faults.size(),
                static_cast<unsigned long long>(history.machine_commands),
                history.tail.empty() ? "" : ("; its torn tail ignored (" + history.tail + ")").c_str());
  } else if (!no_journal) {
    if (journal_path.empty()) {
      const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
      std::tm local{};
      localtime_r(&seconds, &local);
      char name[64];
      std::strftime(name, sizeof name, "stencil-rig-%Y%m%d-%H%M%S.journal", &local);
      journal_path = name;
    }
    journal::JournalStart start;
    start.tables_crc32 = part.header.crc32;
    start.triangle_count = part.header.triangle_count;
    start.unix_time_ns = now_ns;
    start.program = "stencil-rig";
    start.job = job_text;
    if (!journal_writer.open(journal_path, start)) {
      return fail(kExitBadInput, journal_writer.error());
    }
    std::printf("stencil-rig: journal %s\n", journal_path.c_str());
  }

  hal::posix_clock::MonotonicClock clock;
  const hal::cy545::Cy545Config link_config = rig::kCy545;
  hal::cy545::Cy545Link link(port, clock, link_config);
  // Every signal that ends a session ends the job through the cycle's stop (spindle and drivers off):
  // a closed terminal (SIGHUP) or Ctrl-\ (SIGQUIT) as much as Ctrl-C. Nothing survives SIGKILL or a
  // power cut: the next start turns the outputs off first, and the rig needs its hardware watchdog.
  struct sigaction action {};
  action.sa_handler = on_signal;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
    sigaction(signal_number, &action, nullptr);
  }
  if (cpu >= 0 && !app::keep_off_cpu(cpu)) {
    std::fprintf(stderr, "stencil-rig: the other threads could not be kept off CPU %d\n", cpu);
  }
  board::sherline_suzuki::RigJob job;
  job.offset = offset;
  app::Display display;
  std::string display_error;
  if (!display.start(display_options, part, board::sherline_suzuki::rig_controller_config(job), display_error)) {
    // Nothing ran: a fresh journal of nothing goes, a resumed one goes back to the job it held.
    static_cast<void>(journal_writer.close());
    if (resume_path.empty() && !journal_path.empty()) {
      std::remove(journal_path.c_str());
    } else if (!resume_path.empty() && ::truncate(resume_path.c_str(), static_cast<off_t>(history.good_bytes)) != 0) {
      std::fprintf(stderr, "stencil-rig: %s: could not be cut back to the job it held\n", resume_path.c_str());
    }
    return fail(kExitBadInput, display_error);
  }
  job.display = display.feed();
  job.part = &part;
  job.device = device;
  job.machine = &link;
  job.machine_clock = &clock;
  job.offset = offset;
  job.stock = stock;
  job.journal = journal_writer.is_open() ? &journal_writer : nullptr;
  if (!resume_path.empty()) {
    job.resume_from = resume_path;
    job.resume_bytes = history.good_bytes;
  }
  job.interrupted = &interrupted;
  job.duration_s = duration_s;
  job.progress = [](const std::string& line) { std::fprintf(stderr, "stencil-rig: %s\n", line.c_str()); };
  TerminalCommands terminal;
  job.reset_requested = [&terminal] { return terminal.reset_typed(); };
  // The machine thread runs SCHED_FIFO 10 below the cycle (which always preempts it) and above the
  // records thread, which stays SCHED_OTHER with the journal's writes and fsyncs: the machine's
  // updates keep their deadlines whatever the journal's disk does. Refused: it says so and runs on.
  job.prepare_machine_thread = [priority] {
    constexpr int kBelowTheCycle = 10;
    const app::ThreadPriority got =
        app::run_this_thread_fifo(priority > kBelowTheCycle ? priority - kBelowTheCycle : 1, "the machine thread");
    if (!got.message.empty()) {
      std::fprintf(stderr, "stencil-rig: %s\n", got.message.c_str());
    }
  };
  // Nothing turns the spindle on unattended: once homed, the operator types 'start' at the terminal.
  job.confirm_spindle = [&terminal] {
    std::printf("stencil-rig: homed. Hold the handle still near the tool, then type 'start' and Enter to turn the "
                "spindle on (Ctrl-C ends)\n");
    std::fflush(stdout);
    while (!interrupted.load()) {
      const TerminalCommands::Word word = terminal.next_word();
      if (word == TerminalCommands::Word::Start) {
        return true;
      }
      if (word == TerminalCommands::Word::Closed) {
        std::fprintf(stderr, "stencil-rig: no operator at the terminal (its input is closed): the spindle stays off\n");
        return false;
      }
      usleep(100'000);
    }
    return false;
  };
  std::printf("stencil-rig: homing the mill (Ctrl-C stops it); the spindle starts only once you type 'start'\n");
  std::fflush(stdout);
  const app::RealtimeOptions options{priority, cpu, require_rt};
  const board::sherline_suzuki::RigResult result = board::sherline_suzuki::run_rig(
      job, [&](hal::MonotonicNs period_ns, const std::atomic<bool>& stop,
               const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>& cycle, std::string& refused) {
        const app::RealtimeSetup setup = app::run_periodic(options, period_ns, stop, cycle, [](const std::string& line) {
          std::fprintf(stderr, "stencil-rig: %s\n", line.c_str());
        });
        refused = setup.refused.empty() ? "" : "--require-rt: " + setup.refused;
        return setup.refused.empty();
      });
  display.stop();
  if (journal_writer.is_open() && result.started) {
    static_cast<void>(journal_writer.append_end(result.cycles, result.safe_state));  // an orderly end, not a kill
  }
  const bool journal_closed = !journal_writer.is_open() || journal_writer.close();
  if (!result.started) {
    // Nothing ran: a fresh journal of nothing goes, a resumed one goes back to the job it held.
    if (resume_path.empty() && !journal_path.empty()) {
      std::remove(journal_path.c_str());
    } else if (!resume_path.empty() && ::truncate(resume_path.c_str(), static_cast<off_t>(history.good_bytes)) != 0) {
      std::fprintf(stderr, "stencil-rig: %s: could not be cut back to the job it held\n", resume_path.c_str());
    }
    const std::string link_error = link.last_error();
    return fail(kExitNotStarted, result.error + (link_error.empty() ? "" : ": " + link_error));
  }
  const char* reason = control::safe_reason_name(result.safe_state);
  std::printf("stencil-rig: ran %.1f s, %llu cycles, %llu overruns, %llu periods skipped; wake-up p99 %.0f us, p99.9 %.0f us, "
              "max %.0f us; max force %.2f N; %llu machine updates, max lag %.3f mm; the model has %.1f mm3 removed\n"
              "stencil-rig: ended in the safe state: %s; faults: %s (%llu safe-state entries, %llu resets taken, %llu refused)\n",
              result.run_s, static_cast<unsigned long long>(result.cycles), static_cast<unsigned long long>(result.overruns),
              static_cast<unsigned long long>(result.missed_periods), result.wakeup_p99_us, result.wakeup_p999_us,
              result.wakeup_max_us, result.max_force_n, static_cast<unsigned long long>(result.machine_updates),
              result.machine_max_lag_mm, result.model_removed_mm3, reason,
              result.first_fault == control::SafeReason::None ? "none" : control::safe_reason_name(result.first_fault),
              static_cast<unsigned long long>(result.safe_state_entries),
              static_cast<unsigned long long>(result.resets_accepted), static_cast<unsigned long long>(result.resets_refused));
  if (!result.error.empty()) {
    std::fprintf(stderr, "stencil-rig: %s\n", result.error.c_str());
  }
  if (!result.machine_stop_confirmed) {
    std::fprintf(stderr, "stencil-rig: WARNING: the mill's spindle and drivers could not be confirmed off (%s): switch the "
                 "mill's power off\n", link.last_error());
  }
  if (!journal_closed) {
    std::fprintf(stderr, "stencil-rig: %s\n", journal_writer.error().c_str());
  }
  if (!report_path.empty()) {
    const nlohmann::json report = {
        {"cycles", result.cycles},
        {"overruns", result.overruns},
        {"missed_periods", result.missed_periods},
        {"wakeup_latency_us", {{"p99", result.wakeup_p99_us}, {"p999", result.wakeup_p999_us}, {"max", result.wakeup_max_us}}},
        {"compute_us", {{"p99", result.compute_p99_us}, {"max", result.compute_max_us}}},
        {"max_force_n", result.max_force_n},
        {"max_offset_mm", result.max_offset_mm},
        {"machine", {{"updates", result.machine_updates}, {"max_lag_mm", result.machine_max_lag_mm},
                     {"stop_confirmed", result.machine_stop_confirmed}}},
        {"stock_model", {{"removed_volume_mm3", result.model_removed_mm3}}},
        {"safe_state", reason},
        {"first_fault", result.first_fault == control::SafeReason::None ? nlohmann::json(nullptr)
                                                                          : nlohmann::json(control::safe_reason_name(result.first_fault))},
        {"resets", {{"accepted", result.resets_accepted}, {"refused", result.resets_refused}}},
        {"run_s", result.run_s},
        {"job", {{"runs", result.earlier.segments + 1},
                 {"total_cycles", result.earlier.cycles + result.cycles},
                 {"earlier_safe_states", result.earlier.faults.size()},
                 {"earlier_machine_commands", result.earlier.machine_commands},
                 {"touched_recorded", result.earlier.touched_recorded},
                 {"touched_rebuilt", result.touched_rebuilt}}}};
    std::ofstream out(report_path);
    if (!(out << report.dump(2) << "\n")) {
      return fail(kExitBadInput, report_path + ": cannot be written");
    }
  }
  const bool asked = result.safe_state == control::SafeReason::Stopped && result.first_fault == control::SafeReason::None &&
                     result.error.empty() && journal_closed && result.machine_stop_confirmed;
  return asked ? 0 : kExitNotStarted;
}
