#include "firmware/programs/rig_options.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sherline_suzuki/rig_devices.hpp"
#include "board/sherline_suzuki/table_fit.hpp"
#include "firmware/programs/output_probe.hpp"

namespace stencil::app {
namespace {

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

void add_job_options(CLI::App& app, RigOptions& o) {
  app.add_option("--config", o.config_path,
                 "the rig's configuration file (TOML, e.g. /etc/stencil/rig.toml; the example with every key: "
                 "board/sherline_suzuki/rig.toml): checked before anything is opened. Without it, the compiled-in "
                 "Sherline/Suzuki rig; the options below override the file");
  app.add_flag("--config-keys", o.config_keys, "print every key of the configuration file with its type, unit and range, and exit");
  app.add_flag("--commission", o.commission,
               "commission a new or changed configuration instead of running a job (spindle off, no haptic device): "
               "homes, then moves each axis into its travel and back while you type a dial indicator's readings; "
               "says what disagrees with the file (axis sign, steps per mm) and proposes the backlash line");
  app.add_option("--tables", o.tables_path, "the part's .stbl (required for a job)");
  app.add_option("--serial", o.serial_path, "the CY545's serial port, e.g. /dev/ttyS0 (default: the file's machine.serial_port)");
  app.add_option("--haptic", o.haptic, "the haptic link: pio:/dev/uioN or can:IFACE (default: the file's haptic.link)");
  app.add_flag("--require-rt", o.require_rt, "refuse to run without PREEMPT_RT and SCHED_FIFO");
  app.add_option("--priority", o.priority, "the cycle thread's SCHED_FIFO priority (default: the file's threads.cycle_priority)")
      ->check(CLI::Range(2, 99))
      ->capture_default_str();
  app.add_option("--cpu", o.cpu, "pin the cycle thread to this CPU, the other threads kept off it (default: the file's threads.cycle_cpu)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--work-offset", o.offset_text,
                 "X,Y,Z: where the tool tip is in the part's coordinates (mm) with the machine at home, from the "
                 "touch-off (default: the file's job.work_offset_mm)")
      ->capture_default_str();
  app.add_option("--tool-stick-out", o.stick_out, "the tool's stick-out below the holder (mm); with --reference-stick-out")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--reference-stick-out", o.reference_stick_out,
                 "the stick-out of the tool the touch-off was made with (mm): a longer tool puts the tip lower")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--stock", o.stock_text, "the stock block X0,Y0,Z0,X1,Y1,Z1 in world mm (default: the whole workspace)");
}

void add_record_options(CLI::App& app, RigOptions& o) {
  app.add_option("--report", o.report_path,
                 "write the run's figures here as JSON, used as given (default: report.json in the job's folder; a "
                 "--resume's report-resume-N.json, N its run, in its journal's folder)");
  app.add_option("--journal", o.journal_path,
                 "record the job here: every cycle's sample, virtual tool and force, every machine command (written "
                 "before it is sent), every safe-state event; used as given (default: job.journal in the job's folder)");
  app.add_flag("--no-journal", o.no_journal, "record no journal (the job cannot be resumed)");
  app.add_option("--gcode", o.gcode_path,
                 "at the end, write the path the mill was commanded as a G-code program any CNC can run (as "
                 "stencil-journal gcode writes it from the job's journal: mm, absolute, work coordinates, G61)");
  add_job_folder_options(app, o.jobs, "stencil-rig", "job.journal and report.json, checked before anything moves",
                         "A --resume writes in its journal's folder");
  app.add_option("--resume", o.resume_path,
                 "carry on the job this journal recorded (after a crash, a kill or a safe state), with the same --tables, "
                 "--work-offset, stick-outs and --stock: the touched set and the model of the machined stock are rebuilt "
                 "from it, the mill homes again (Z first, out of the stock) and the cut carries on from wherever the "
                 "operator takes the handle; the journal carries on in the same file and the report covers the whole job");
  app.add_option("--duration", o.duration_s, "stop after this many seconds (default: until SIGINT, SIGTERM, SIGHUP or SIGQUIT)")
      ->check(CLI::NonNegativeNumber);
}

// The stock: by default the whole workspace [0, travel] (checked against the travel from the work
// offset once the tables are in), else inside that travel.
bool read_stock(const std::array<double, 3>& workspace, const std::array<double, 3>& low,
                const std::array<double, 3>& high, const std::string& text, control::StockBlock& stock,
                std::string& error) {
  stock = {{0.0, 0.0, 0.0}, {workspace[0], workspace[1], workspace[2]}};
  if (text.empty()) {
    return true;
  }
  std::vector<double> numbers;
  bool inside = parse_numbers(text, numbers, 6);
  for (int axis = 0; inside && axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    inside = numbers[a] >= low[a] && numbers[a] < numbers[a + 3] && numbers[a + 3] <= high[a];
  }
  if (!inside) {
    char workspace_text[160];
    std::snprintf(workspace_text, sizeof workspace_text, "[%g,%g]x[%g,%g]x[%g,%g]", low[0], high[0], low[1], high[1],
                  low[2], high[2]);
    error = "--stock " + text + ": expected X0,Y0,Z0,X1,Y1,Z1 in mm with each high above its low, inside the workspace " +
            workspace_text + " (the travel from the work offset)";
    return false;
  }
  stock = {{numbers[0], numbers[1], numbers[2]}, {numbers[3], numbers[4], numbers[5]}};
  return true;
}

}  // namespace

void add_rig_options(CLI::App& app, RigOptions& options) {
  namespace rig = board::sherline_suzuki;
  char home_text[64];
  std::snprintf(home_text, sizeof home_text, "%g,%g,%g", rig::kHomeWorldMm[0], rig::kHomeWorldMm[1], rig::kHomeWorldMm[2]);
  options.offset_text = home_text;  // the machine's home before any touch-off
  add_job_options(app, options);
  add_record_options(app, options);
  add_display_options(app, options.display);
}

bool check_rig_options(const RigOptions& o, board::sherline_suzuki::WorkOffset& offset, control::StockBlock& stock,
                       std::string& error) {
  if (!check_display_options(o.display, error)) {
    return false;
  }
  // (CLI11's range check lets a NaN through: every comparison with it is false.)
  if (!std::isfinite(o.stick_out) || !std::isfinite(o.reference_stick_out)) {
    error = "--tool-stick-out and --reference-stick-out: expected a length in mm from 0 to 100";
    return false;
  }
  std::vector<double> numbers;
  if (!parse_numbers(o.offset_text, numbers, 3)) {
    error = "--work-offset " + o.offset_text + ": expected X,Y,Z in mm";
    return false;
  }
  offset.home_world_mm = Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
  offset.tool_stick_out_mm = o.stick_out;
  offset.reference_stick_out_mm = o.reference_stick_out;
  std::array<double, 3> low{}, high{};
  board::sherline_suzuki::configured_travel(
      o.config.facts, {{numbers[0], numbers[1], numbers[2]}, o.stick_out, o.reference_stick_out}, low, high);
  if (!read_stock(o.config.facts.workspace_mm, low, high, o.stock_text, stock, error) || (!o.report_path.empty() && !probe_writable(o.report_path, error))) {
    return false;
  }
  if (!board::sherline_suzuki::is_haptic_link_name(o.haptic)) {
    error = "--haptic " + o.haptic + ": expected pio:/dev/uioN or can:IFACE";
    return false;
  }
  if (!o.gcode_path.empty() && o.no_journal) {
    error = "--gcode writes the program from the job's journal: not with --no-journal";
    return false;
  }
  if (!o.resume_path.empty() && (!o.journal_path.empty() || o.no_journal)) {
    error = "--resume carries on in the journal it resumes: no --journal or --no-journal with it";
    return false;
  }
  if (!o.resume_path.empty() && !o.jobs.out_dir.empty()) {
    error = "--out-dir: a --resume writes in its journal's folder";
    return false;
  }
  return true;
}

bool apply_rig_config(const CLI::App& app, RigOptions& o, std::string& error) {
  if (!o.config_path.empty() && !board::sherline_suzuki::read_rig_config(o.config_path, o.config, error)) {
    return false;
  }
  const board::sherline_suzuki::RigConfig& c = o.config;
  const bool file = !o.config_path.empty();
  if (app.count("--serial") == 0) o.serial_path = c.serial_port;
  if (app.count("--haptic") == 0) o.haptic = c.haptic_link;
  if (app.count("--priority") == 0 && file) o.priority = c.cycle_priority;
  if (app.count("--cpu") == 0 && file) o.cpu = c.cycle_cpu;
  take_configured_retention(app, o.jobs, c.keep_jobs, c.keep_mb);
  if (app.count("--work-offset") == 0 && file) {
    char text[96];
    std::snprintf(text, sizeof text, "%.17g,%.17g,%.17g", c.work_offset_mm[0], c.work_offset_mm[1], c.work_offset_mm[2]);
    o.offset_text = text;
  }
  // Always below the cycle; without a file, 10 below it as before there was one.
  o.machine_priority = file ? std::min(c.machine_priority, o.priority - 1) : std::max(1, o.priority - 10);
  if (o.tables_path.empty() && !o.commission) {
    error = "--tables: the part's .stbl is required";
  } else if (o.serial_path.empty() && o.config.facts.controller != board::sherline_suzuki::MachineController::Linuxcnc) {
    error = "--serial: the CY545's serial port is required (or machine.serial_port in the --config file)";
  } else if (!o.serial_path.empty() && o.config.facts.controller == board::sherline_suzuki::MachineController::Linuxcnc) {
    error = "--serial: the --config file's mill is LinuxCNC (machine.controller = \"linuxcnc\"), reached over linuxcncrsh, "
            "not a serial port";
  } else if (o.haptic.empty() && !o.commission) {
    error = "--haptic: the haptic link is required (or haptic.link in the --config file)";
  }
  return error.empty();
}

}  // namespace stencil::app
