// Where a job writes, for both controllers: --out-dir (the jobs folder), --keep-jobs and --keep-mb
// (retention), and the new job's own folder made from them before anything moves.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "firmware/services/report/job_folder.hpp"

namespace stencil::app {

struct JobFolderOptions {
  std::string out_dir;      // --out-dir: the jobs folder (empty: the configured folder, else the XDG default)
  unsigned keep_jobs = 50;  // --keep-jobs, else the configuration's job.keep_jobs (0: every job kept)
  unsigned keep_mb = 0;     // --keep-mb, else the configuration's job.keep_mb (0: no size cap)
};

// `program` names the job folders (stencil-sim-YYYYMMDD-HHMMSS); `outputs` says what a job writes in
// its folder, `resumed` where a --resume (and --replay) writes instead.
void add_job_folder_options(CLI::App& app, JobFolderOptions& options, const std::string& program,
                            const std::string& outputs, const std::string& resumed);

// After the configuration is read: its job.keep_jobs and job.keep_mb where the command line gave none.
void take_configured_retention(const CLI::App& app, JobFolderOptions& options, unsigned keep_jobs, unsigned keep_mb);

// A new job's folder under --out-dir, else `configured_folder` (job.output_folder), else the XDG
// default: retention first, each line to `say`. False with the error (naming --out-dir when given).
[[nodiscard]] bool make_job_folder(const JobFolderOptions& options, const std::string& program,
                                   const std::string& configured_folder, report::JobFolder& folder,
                                   const std::function<void(const std::string&)>& say, std::string& error);

}  // namespace stencil::app
