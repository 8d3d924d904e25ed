// stencil-sim's command line: every option with its help, and the checks of how they combine,
// made before anything is read or opened.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "board/sherline_suzuki/commissioning.hpp"
#include "board/sim/fault_injection.hpp"
#include "board/sim/sim_facts.hpp"
#include "board/sim/sim_job.hpp"
#include "firmware/programs/display_option.hpp"
#include "firmware/programs/job_folder_option.hpp"

namespace stencil::app {

struct SimOptions {
  std::string config_path;      // --config: the rig's configuration file (empty: the compiled-in rig)
  std::string mill_truth_path;  // --mill-truth: the simulated mill as it really is (empty: as configured)
  std::string linuxcnc_samples_path;  // --linuxcnc-samples: halsampler's file, with a LinuxCNC --config
  std::optional<board::sim::LinuxcncMill> linuxcnc;  // a --config whose machine.controller is "linuxcnc"
  board::sim::SimRig rig;       // both, read by apply_sim_config
  bool commission = false;      // --commission: commissioning on the simulated rig instead of a job
  board::sherline_suzuki::CommissioningSettings commissioning;  // the file's [commissioning]
  std::uint32_t config_crc32 = 0, mill_truth_crc32 = 0;          // the files', for the journal's job (0: none)
  std::string output_folder;                                     // the file's job.output_folder
  JobFolderOptions jobs;      // --out-dir, --keep-jobs, --keep-mb
  std::string tables_path;    // empty: the baked-in hex prism
  std::string operator_path;  // empty: the pattern
  std::string gcode_operator_path;  // --gcode-operator: a CAM program as the operator's motion
  std::string gcode_direct_path;    // --gcode-direct: a program cut by the simulated mill with no stencil
  double gcode_arc_tolerance_mm = 0.001;
  std::string pattern_name = "raster";
  std::uint64_t seed = 1;
  int moves = 200;
  double duration_s = 0.0;
  bool fast = false;
  double speed = 0.0;         // 0: --fast; 1: real time; other: paced virtual time
  int priority = 80;
  int cpu = -1;
  bool require_rt = false;
  std::string report_path;    // empty: report.json in the job's folder (report-resume-N.json, replay.json)
  bool until_complete = false;
  std::string stock_text;
  std::string inject_text;
  board::sim::FaultInjection fault;  // from inject_text, by check_sim_options
  std::string journal_path;
  bool no_journal = false;
  std::string resume_path;
  std::string replay_path;
  std::string stock_csv_path;
  std::string gcode_path;        // --gcode: the cut written as a program at the end (from the journal)
  std::string device_log_path;
  std::string trace_path;
  std::string script_csv_path;
  std::string transport = "direct";
  // The operator's hand (issue 29): "placed", today's quasi-static hand that places the handle, or a
  // dynamic arm (sim/operator/hand_device_model.hpp) pulling it: relaxed, medium or stiff.
  std::string hand = "placed";
  // The wall's feel from the first cycle, as the operator's commands (journalled, replayed).
  double damping_n_s_per_m = 0.0;
  double friction = 0.0;
  std::string speed_limiting = "cap";
  DisplayOptions display;

  [[nodiscard]] bool real_time() const { return !fast && speed == 1.0; }
};

void add_sim_options(CLI::App& app, SimOptions& options);

// After parsing: how the options combine (and --inject read into `fault`; --replay implies --fast
// unless paced, and no journal). False with the message for the terminal.
[[nodiscard]] bool check_sim_options(const CLI::App& app, SimOptions& options, std::string& error);

// After check_sim_options: --config and --mill-truth read and checked (file, line, key) into `rig`,
// the file's threads under --priority and --cpu unless given. False with the message.
[[nodiscard]] bool apply_sim_config(const CLI::App& app, SimOptions& options, std::string& error);

}  // namespace stencil::app
