// stencil-rig's command line: every option with its help, and what the options say about the job
// (the work offset, the stock), checked before anything is opened.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "board/sherline_suzuki/rig_config.hpp"
#include "board/sherline_suzuki/rig_job.hpp"
#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/programs/display_option.hpp"
#include "firmware/programs/job_folder_option.hpp"
#include "firmware/services/report/provenance.hpp"

namespace stencil::app {

struct RigOptions {
  std::string config_path;    // --config: the rig's file (empty: the compiled-in Sherline/Suzuki rig)
  report::Provenance provenance;  // filled in once the tables are loaded: the report's and the journal's
  bool config_keys = false;   // --config-keys: print every key of the file and exit
  bool commission = false;    // --commission: commission the mill against a dial indicator instead of a job
  board::sherline_suzuki::RigConfig config;  // the file's (or the defaults), with the command line's overrides
  std::string tables_path;
  std::string serial_path;
  std::string haptic;         // pio:/dev/uioN or can:IFACE
  bool require_rt = false;
  int priority = 80;
  int machine_priority = 70;  // the machine thread's, below the cycle's (the file's threads.machine_priority)
  int cpu = -1;
  std::string offset_text;    // default: the rig's home (add_rig_options)
  double stick_out = 0.0;
  double reference_stick_out = 0.0;
  std::string stock_text;     // empty: the whole workspace
  std::string report_path;    // empty: report.json in the job's folder (a --resume's report-resume-N.json)
  std::string gcode_path;     // --gcode: the cut written as a G-code program at the end (from the journal)
  std::string journal_path;   // empty: job.journal in the job's folder
  JobFolderOptions jobs;      // --out-dir, --keep-jobs, --keep-mb
  bool no_journal = false;
  std::string resume_path;
  double duration_s = 0.0;
  DisplayOptions display;
};

void add_rig_options(CLI::App& app, RigOptions& options);

// After parsing: the configuration file read and checked (when --config names one), then the command
// line's --serial, --haptic, --priority, --cpu and --work-offset over it; without a file, --serial and
// --haptic must be given. False with the message (the file, the line, the key) for the terminal.
[[nodiscard]] bool apply_rig_config(const CLI::App& app, RigOptions& options, std::string& error);

// After parsing: the options checked and read into the job's work offset and stock block (the
// report's path found writable). False with the message for the terminal.
[[nodiscard]] bool check_rig_options(const RigOptions& options, board::sherline_suzuki::WorkOffset& offset,
                                     control::StockBlock& stock, std::string& error);

}  // namespace stencil::app
