#include "firmware/programs/sim_options.hpp"

#include "board/sherline_suzuki/rig_config.hpp"

#include "sim/operator/operator_script.hpp"

namespace stencil::app {
namespace {

void add_operator_options(CLI::App& app, SimOptions& o) {
  app.add_option("--tables", o.tables_path, "the part's .stbl (default: the baked-in hex prism, ball end mill d = 3 mm)");
  app.add_option("--operator", o.operator_path, "the operator's script: CSV rows t_s,x_mm,y_mm,z_mm[,a_rad,b_rad] in device space");
  app.add_option("--gcode-operator", o.gcode_operator_path,
                 "a CAM program (G-code) as the operator's motion, interpreted by LinuxCNC's rs274: the hand follows "
                 "its moves at their feeds (at most what the mill can follow), the stencil keeps the tool out of the "
                 "part, and the report lists each source line whose move it refused or shortened, with how deep that "
                 "move would have gone (gcode.refused). Refused, naming the line: cutter compensation, canned cycles, "
                 "G33, probing, a tool change after the first move");
  app.add_option("--gcode-direct", o.gcode_direct_path,
                 "cut a G-code program (interpreted by rs274) straight into the simulated stock with no stencil and "
                 "no controller: what the program does on a mill as it is; the report, picture and --stock-csv as a "
                 "job's (a stencil-sim --gcode program cut again must leave the job's stock)");
  app.add_option("--gcode-arc-tolerance", o.gcode_arc_tolerance_mm,
                 "mm: a G-code arc is followed as chords that stray from it by at most this")
      ->check(CLI::Range(1e-5, 0.1))
      ->capture_default_str();
  app.add_option("--pattern", o.pattern_name, "the operator's pattern when there is no --operator file")
      ->check(CLI::IsMember({"raster", "plunge", "thinwall", "random"}))
      ->capture_default_str();
  app.add_option("--seed", o.seed, "the random pattern's seed")->capture_default_str();
  app.add_option("--moves", o.moves, "the random pattern's number of moves (200 take about 40 simulated minutes)")
      ->check(CLI::Range(1, 1'000'000))
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "simulated seconds to run (default: the script's length)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--fast", o.fast, "virtual clock, as fast as the machine allows, deterministic");
  app.add_option("--speed", o.speed,
                 "N x real time. 1: the cycle on a SCHED_FIFO thread at 1 kHz and the machine and the fake CY545 on "
                 "threads of their own, on the wall clock (what make latency measures); any other N: the --fast "
                 "virtual clock held to N simulated seconds per second, deterministic, so a person can watch")
      ->check(CLI::Range(1e-3, 1e6));
  app.add_option("--priority", o.priority, "real time: the cycle thread's SCHED_FIFO priority")
      ->check(CLI::Range(1, 99))
      ->capture_default_str();
  app.add_option("--cpu", o.cpu, "real time: pin the cycle thread to this CPU")->check(CLI::NonNegativeNumber);
  app.add_flag("--require-rt", o.require_rt, "real time: refuse to run without SCHED_FIFO and locked memory");
  app.add_option("--report", o.report_path,
                 "the JSON report, used as given; the picture goes beside it (default: report.json in the job's "
                 "folder; a --resume's report-resume-N.json, N its run, a --replay's replay.json, in the journal's folder)");
  app.add_flag("--until-complete", o.until_complete,
               "end once every reachable triangle is touched and the mill has caught up with the virtual tool");
  app.add_option("--stock", o.stock_text, "the stock block X0,Y0,Z0,X1,Y1,Z1 in world mm (default: the part's box grown by 2 mm)");
  app.add_option("--inject", o.inject_text,
                 "KIND@S: inject one fault S simulated seconds into the job (--fast or --speed N other than 1); KIND is " +
                     board::sim::fault_kind_names(board::sim::FaultKindList::Sentence) +
                     "; the report's fault section says when the safe state, zero force and the stopped mill followed");
}

void add_record_options(CLI::App& app, SimOptions& o) {
  app.add_option("--journal", o.journal_path,
                 "record the job here: every cycle's device sample, virtual tool and force, every machine command "
                 "(written before it is sent) and every safe-state event, with a CRC-32 each, synced to the disk every "
                 "second and at once on a safe state; used as given (default: job.journal in the job's folder; about "
                 "40 MB per simulated hour)");
  add_job_folder_options(app, o.jobs, "stencil-sim",
                         "job.journal, report.json and its picture, and any --trace, --stock-csv, --script-csv or "
                         "--device-process file given as a bare name (a path with a slash is used as given)",
                         "A --resume and a --replay write in their journal's folder instead");
  app.add_flag("--no-journal", o.no_journal, "record no journal (the job cannot be resumed)");
  app.add_option("--resume", o.resume_path,
                 "carry on the job this journal recorded (after a crash, a kill or a safe state), given the same "
                 "--tables, --pattern, --seed, --operator and --stock: the touched set and the stock as machined are "
                 "rebuilt from it, the machine homes again, the simulated operator goes back across at home's height "
                 "and down to where the cut stopped and carries on with its script; the journal carries on in the "
                 "same file and the report covers the whole job (--duration is then the whole job's)");
  app.add_option("--replay", o.replay_path,
                 "re-run the job this journal recorded, deterministically, on the virtual clock: each cycle reads "
                 "exactly what the recorded cycle read from the device (every run of a resumed job in turn, each "
                 "from the state the runs before it left); says whether every cycle's virtual tool came out bit for "
                 "bit as recorded (exit 0) or where it first differed (exit 3). Writes the report and no journal");
  app.add_option("--stock-csv", o.stock_csv_path,
                 "write the machined stock's heights here at the end: one row of the Z-map per line (y rising), "
                 "mm, cells of 0.05 mm from the stock's low corner");
  app.add_option("--device-process", o.device_log_path,
                 "LOG: with --haptic-transport pio only: the simulated device and the operator's hand run in a process of "
                 "their own (on the virtual clock in lockstep with the cycle, so the job is the same job; in real time "
                 "on the wall clock), so that if this one dies, even by SIGKILL, the device's own host watchdog zeroes "
                 "the force; the device writes to LOG how long that took");
  app.add_option("--script-csv", o.script_csv_path,
                 "write the operator's script (the pattern's or --operator's, after a --resume's way back) to this CSV "
                 "in the --operator format before the job runs: a random job's moves, to cut a piece out as a job of its own");
  app.add_option("--gcode", o.gcode_path,
                 "at the end, write the path the mill was commanded as a G-code program any CNC can run (as "
                 "stencil-journal gcode writes it from the job's journal: mm, absolute, work coordinates, G61)");
  app.add_option("--trace", o.trace_path, "write the simulated mill's true path corners to this CSV (t_s,x_mm,y_mm,z_mm)");
  app.add_option("--haptic-transport", o.transport,
                 "how the cycle reaches the simulated device: in process, or through the real PIO shared-memory or "
                 "SocketCAN code over a memfd or a socketpair")
      ->check(CLI::IsMember({"direct", "pio", "can"}))
      ->capture_default_str();
  app.add_option("--hand", o.hand,
                 "the operator's hand on the handle: placed (it puts the handle where its script and the force "
                 "say, today's), or an arm that pulls the handle as a mass-spring-damper with the device's own mass "
                 "and friction, integrated at 20 kHz: relaxed (0.1 kg, 50 N/m, 1 N s/m), medium (0.3 kg, 300 N/m, "
                 "5 N s/m) or stiff (0.5 kg, 1000 N/m, 15 N s/m)")
      ->check(CLI::IsMember({"placed", "relaxed", "medium", "stiff"}))
      ->capture_default_str();
  app.add_option("--damping", o.damping_n_s_per_m,
                 "N s/m of virtual damping in the wall from the first cycle, with the passivity controller (0: none; "
                 "the cycle takes at most 100), as the operator's command set_damping: journalled and replayed")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--friction", o.friction,
                 "the Coulomb friction coefficient of the virtual tool on the part from the first cycle (0 to 1), as "
                 "the operator's command set_friction")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--speed-limiting", o.speed_limiting,
                 "cap: the virtual tool's speed capped at the mill's; penalty: that, and damping on the hand that "
                 "rises as it nears that speed, as the operator's command set_speed_limiting from the first cycle")
      ->check(CLI::IsMember({"cap", "penalty"}))
      ->capture_default_str();
}

// --inject KIND@SECONDS, on the virtual clock only.
bool check_inject(SimOptions& o, std::string& error) {
  const std::size_t at = o.inject_text.find('@');
  double at_s = 0.0;
  if (at == std::string::npos || !board::sim::parse_fault_kind(o.inject_text.substr(0, at), o.fault.kind) ||
      !sim::parse_finite_field(o.inject_text.substr(at + 1), at_s) || at_s < 0.0) {
    error = "--inject " + o.inject_text + ": expected KIND@SECONDS, KIND one of " +
            board::sim::fault_kind_names(board::sim::FaultKindList::Plain);
    return false;
  }
  o.fault.at_s = at_s;
  if (o.fault.kind == board::sim::FaultKind::CanBadFrames && o.transport != "can") {
    error = "--inject can-bad-frames: the bad frames are CAN frames (--haptic-transport can)";
    return false;
  }
  if (o.speed == 1.0) {
    error = "--inject: faults are injected on the virtual clock (--fast or --speed N other than 1)";
    return false;
  }
  return true;
}

}  // namespace

void add_sim_options(CLI::App& app, SimOptions& options) {
  app.add_option("--config", options.config_path,
                 "a rig's configuration file (TOML, as stencil-rig --config; every key: board/sherline_suzuki/rig.toml): "
                 "the simulation runs a copy of that rig, its mill as the file says unless --mill-truth "
                 "(default: the compiled-in Sherline/Suzuki rig)");
  app.add_option("--linuxcnc-samples", options.linuxcnc_samples_path,
                 "with a --config whose machine.controller is \"linuxcnc\" (the real LinuxCNC as the mill, --speed 1 "
                 "only): halsampler's file of every servo period's joint positions (sim/linuxcnc_mill/linuxcnc-sim.sh "
                 "start DIR writes DIR/samples.txt), the ground truth of what was machined");
  app.add_option("--mill-truth", options.mill_truth_path,
                 "a second configuration file: the simulated mill as it really is (its axis signs, steps per mm, "
                 "backlash, travel, wiring), where it differs from what --config tells the controller");
  app.add_flag("--commission", options.commission,
               "commission the simulated rig instead of running a job: it homes, then moves each axis into its "
               "travel and back while a simulated machinist reads a dial indicator from the mill's truth; findings "
               "(a wrong axis sign, steps per mm, backlash) on stdout, exit status 3 when there are any");
  add_operator_options(app, options);
  add_record_options(app, options);
  add_display_options(app, options.display);
}

bool check_sim_options(const CLI::App& app, SimOptions& o, std::string& error) {
  if (!check_display_options(o.display, error)) {
    return false;
  }
  if ((o.fast || (o.speed > 0.0 && o.speed != 1.0)) &&
      (app.count("--priority") + app.count("--cpu") + app.count("--require-rt")) > 0) {
    error = "--priority, --cpu and --require-rt are for the real-time threads of --speed 1 only";
    return false;
  }
  if (o.commission) {
    if (!o.replay_path.empty() || !o.resume_path.empty() || !o.inject_text.empty() || o.speed > 0.0 ||
        o.display.requested()) {
      error = "--commission runs on the virtual clock by itself: no --replay, --resume, --inject, --speed or display with it";
      return false;
    }
    o.fast = true;
    o.no_journal = true;
  }
  if (!o.inject_text.empty() && !check_inject(o, error)) {
    return false;
  }
  if (!o.replay_path.empty()) {
    if (!o.resume_path.empty() || !o.journal_path.empty() || !o.inject_text.empty() ||
        app.count("--device-process") > 0 || o.speed == 1.0 || o.display.requested()) {
      error = "--replay runs the recorded job on the virtual clock by itself: no --resume, --journal, --inject, "
              "--device-process, --hmi, --display-socket or --speed 1 with it";
      return false;
    }
    o.fast = o.fast || o.speed == 0.0;
    o.no_journal = true;
  }
  if (!o.gcode_direct_path.empty() && !o.fast && o.speed == 0.0) {
    o.fast = true;  // no clock to speak of: the program's moves are cut one after another
  }
  if (!o.jobs.out_dir.empty() && (!o.resume_path.empty() || !o.replay_path.empty())) {
    error = "--out-dir: a --resume or a --replay writes in its journal's folder";
  } else if (!o.resume_path.empty() && (!o.journal_path.empty() || o.no_journal)) {
    error = "--resume carries on in the journal it resumes: no --journal or --no-journal with it";
  } else if (o.no_journal && !o.journal_path.empty()) {
    error = "--journal and --no-journal: choose one";
  } else if (!o.gcode_operator_path.empty() && !o.operator_path.empty()) {
    error = "--operator and --gcode-operator: choose one";
  } else if (!o.gcode_direct_path.empty() &&
             (!o.operator_path.empty() || !o.gcode_operator_path.empty() || !o.resume_path.empty() || !o.replay_path.empty() ||
              !o.inject_text.empty() || !o.gcode_path.empty() || o.commission || o.display.requested() ||
              app.count("--device-process") + app.count("--journal") + app.count("--linuxcnc-samples") > 0)) {
    error = "--gcode-direct cuts the program with no controller: no --operator, --gcode-operator, --resume, --replay, "
            "--inject, --gcode, --commission, --journal, --device-process, --linuxcnc-samples or display with it";
  } else if (!o.gcode_path.empty() && o.no_journal) {
    error = "--gcode writes the program from the job's journal: not with --no-journal, --replay or --commission";
  } else if (!o.device_log_path.empty() && (o.transport != "pio" || !o.inject_text.empty())) {
    error = "--device-process: the device runs in its own process only with --haptic-transport pio and no --inject";
  } else if (!o.device_log_path.empty() && o.hand != "placed") {
    error = "--device-process: the device's own process moves the placed hand only (no --hand " + o.hand + ")";
  } else if (o.fast == (o.speed > 0.0)) {
    error = o.fast ? "--fast and --speed: choose one" : "pass --fast (virtual time) or --speed N (N x real time)";
  }
  if (!o.gcode_direct_path.empty()) {
    o.no_journal = true;  // no controller, nothing to record: the report and the stock are the result
  }
  return error.empty();
}

namespace {

// The real LinuxCNC as the mill: real time only, its samples the ground truth, and none of what needs
// the simulated mill (its truth, injected faults, resuming or replaying its journal, commissioning).
bool apply_linuxcnc(const CLI::App& app, SimOptions& o, const board::sherline_suzuki::RigConfig& config, std::string& error) {
  if (o.speed != 1.0 || o.fast) {
    error = "--config " + o.config_path + ": a LinuxCNC mill (machine.controller = \"linuxcnc\") runs in real time: pass --speed 1";
  } else if (o.linuxcnc_samples_path.empty()) {
    error = "--config " + o.config_path +
            ": a LinuxCNC mill needs --linuxcnc-samples FILE, halsampler's file of its joint positions (the ground truth)";
  } else if (!o.mill_truth_path.empty() || !o.inject_text.empty() || !o.resume_path.empty() || !o.replay_path.empty() ||
             o.commission || app.count("--device-process") > 0) {
    error = "--config " + o.config_path +
            ": with a LinuxCNC mill there is no simulated mill: no --mill-truth, --inject, --resume, --replay, "
            "--commission or --device-process";
  }
  if (!error.empty()) {
    return false;
  }
  o.linuxcnc = board::sim::LinuxcncMill{board::sherline_suzuki::linuxcnc_config(config.facts), o.linuxcnc_samples_path};
  return true;
}

}  // namespace

bool apply_sim_config(const CLI::App& app, SimOptions& o, std::string& error) {
  board::sherline_suzuki::RigConfig config;
  if (!o.config_path.empty()) {
    if (!board::sherline_suzuki::read_rig_config(o.config_path, config, error)) {
      return false;
    }
    o.rig.facts = config.facts;
    o.rig.home_world_mm = config.work_offset_mm;
    o.rig.mill_truth = config.facts;
    o.commissioning = config.commissioning;
    o.config_crc32 = config.file_crc32;
    o.output_folder = config.output_folder;
    take_configured_retention(app, o.jobs, config.keep_jobs, config.keep_mb);
    if (app.count("--priority") == 0) o.priority = config.cycle_priority;
    if (app.count("--cpu") == 0) o.cpu = config.cycle_cpu;
    if (config.facts.controller == board::sherline_suzuki::MachineController::Linuxcnc) {
      return apply_linuxcnc(app, o, config, error);
    }
  }
  if (!o.linuxcnc_samples_path.empty()) {
    error = "--linuxcnc-samples: only with a --config whose machine.controller is \"linuxcnc\"";
    return false;
  }
  if (!o.mill_truth_path.empty()) {
    board::sherline_suzuki::RigConfig truth;
    if (!board::sherline_suzuki::read_rig_config(o.mill_truth_path, truth, error)) {
      error = "--mill-truth: " + error;
      return false;
    }
    o.rig.mill_truth = truth.facts;
    o.mill_truth_crc32 = truth.file_crc32;
  }
  return true;
}

}  // namespace stencil::app
