// The job folder's options and the folder made from them.
#include "firmware/programs/job_folder_option.hpp"

#include <cstdint>
#include <cstdlib>
#include <ctime>

namespace stencil::app {

void add_job_folder_options(CLI::App& app, JobFolderOptions& o, const std::string& program, const std::string& outputs,
                            const std::string& resumed) {
  std::string out_dir_help = "DIR: the jobs folder (made with its parents if missing). Each job writes in a folder of its own there, ";
  out_dir_help.append(program)
      .append("-YYYYMMDD-HHMMSS (its local start time; -2, -3 ... when taken): ")
      .append(outputs)
      .append("; DIR/latest links to the newest. ")
      .append(resumed)
      .append(" (default: the --config file's job.output_folder, else $XDG_STATE_HOME/stencil/jobs, else "
              "~/.local/state/stencil/jobs)");
  app.add_option("--out-dir", o.out_dir, out_dir_help);
  app.add_option("--keep-jobs", o.keep_jobs,
                 "N: as a new job starts, the oldest job folders in the jobs folder beyond the newest N (this one "
                 "counted) are removed, each said; never one whose journal's last run has no End (killed or "
                 "still running: it may be resumed). 0: keep every job (default: the --config file's "
                 "job.keep_jobs, else 50)")
      ->check(CLI::Range(0U, 100000U));
  app.add_option("--keep-mb", o.keep_mb,
                 "M: as --keep-jobs, the newest job folders that fit in M MB kept, older ones removed (default: the "
                 "--config file's job.keep_mb, else 0: no size cap)")
      ->check(CLI::Range(0U, 100000000U));
}

void take_configured_retention(const CLI::App& app, JobFolderOptions& o, unsigned keep_jobs, unsigned keep_mb) {
  if (app.count("--keep-jobs") == 0) {
    o.keep_jobs = keep_jobs;
  }
  if (app.count("--keep-mb") == 0) {
    o.keep_mb = keep_mb;
  }
}

bool make_job_folder(const JobFolderOptions& o, const std::string& program, const std::string& configured_folder,
                     report::JobFolder& folder, const std::function<void(const std::string&)>& say, std::string& error) {
  const report::JobFolderRequest request{
      program,
      o.out_dir.empty() ? report::default_jobs_folder(configured_folder, std::getenv("XDG_STATE_HOME"), std::getenv("HOME"))
                        : o.out_dir,
      {o.keep_jobs, std::uint64_t{o.keep_mb} * 1'000'000U}};
  if (!folder.make(request, std::time(nullptr), say, error)) {
    error = (o.out_dir.empty() ? "" : "--out-dir: ") + error;
    return false;
  }
  return true;
}

}  // namespace stencil::app
