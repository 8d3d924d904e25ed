// A job's own folder: every output of a job and of each --resume of it (report, picture, journal,
// trace) in one folder named after its start, under a jobs folder (--out-dir, the configuration's
// job.output_folder, else $XDG_STATE_HOME/stencil/jobs), with a `latest` link to the newest; and the
// retention that keeps that folder from growing without end, never removing a job that may still be
// resumed. Init-time only: files and folders, nothing of it is called from the cycle.
#pragma once

#include <cstdint>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

namespace stencil::report {

// The jobs folder when none is given: `configured` (job.output_folder) when not empty, else
// $XDG_STATE_HOME/stencil/jobs, or $HOME/.local/state/stencil/jobs when XDG_STATE_HOME is unset,
// empty or not absolute (the XDG Base Directory rule). Empty when HOME is not set either.
[[nodiscard]] std::string default_jobs_folder(const std::string& configured, const char* xdg_state_home,
                                              const char* home);

// "<program>-YYYYMMDD-HHMMSS" in local time.
[[nodiscard]] std::string job_folder_name(const std::string& program, std::time_t start);

// Where a job folder's name puts it among the others: its start (YYYYMMDD-HHMMSS), then the number
// of the `-N` added when a job of the same second had the name already (1: none).
struct JobFolderOrder {
  std::string start;
  unsigned number = 1;
  [[nodiscard]] bool operator<(const JobFolderOrder& other) const {
    return start != other.start ? start < other.start : number < other.number;
  }
};

// True when `name` is a job folder's: a program name of lower-case letters and dashes, then
// -YYYYMMDD-HHMMSS, then perhaps -N (N from 2).
[[nodiscard]] bool parse_job_folder_name(const std::string& name, JobFolderOrder& order);

// One job folder in the jobs folder, as retention sees it.
struct JobEntry {
  std::string name;       // the folder's name (not its path)
  bool finished = false;  // its journal's last run ended in order (an End record); no journal: its report exists
  std::uint64_t bytes = 0;
};

struct RetentionRule {
  unsigned keep_jobs = 50;       // the newest jobs kept, the one starting counted (0: every job)
  std::uint64_t keep_bytes = 0;  // the jobs' size kept, newest first (0: no cap)
};

enum class JobFate : std::uint8_t {
  Kept,             // within the rule
  Removed,          // beyond it, finished
  KeptInterrupted,  // beyond it, but its last run has no End: it may still be resumed, never removed
};

// The decision alone: each of `oldest_first` (the jobs already there; a new one is about to start
// and counts as one of keep_jobs) within the rule or not, and what becomes of it. An interrupted job
// counts toward both limits like any other (it takes its place and its space), and is kept.
[[nodiscard]] std::vector<JobFate> retention_fates(const std::vector<JobEntry>& oldest_first, const RetentionRule& rule);

// The job folders in `jobs_folder` (a job folder's name, a real folder, with job.journal or
// report.json inside), oldest first, with their sizes; `finished` is left false (see job_finished).
[[nodiscard]] std::vector<JobEntry> list_job_folders(const std::string& jobs_folder);

// Whether the job in `job_folder` ended: its job.journal's last run (after its last Start or Resume)
// has an End record; a journal that cannot be read counts as not ended. Without a journal, whether
// its report.json exists.
[[nodiscard]] bool job_finished(const std::string& job_folder);

// Retention over `jobs_folder` before a new job's folder is made: lists, decides, reads the journals
// only of the jobs beyond the rule, removes the finished ones. One line each for `say`:
// "jobs: removed <folder> (finished, N MB)", "jobs: kept <folder>: interrupted, may be resumed",
// "jobs: could not remove <folder>: <reason>".
void apply_retention(const std::string& jobs_folder, const RetentionRule& rule,
                     const std::function<void(const std::string&)>& say);

// Where a program's job writes.
struct JobFolderRequest {
  std::string program;      // "stencil-sim", "stencil-rig": the start of the folder's name
  std::string jobs_folder;  // --out-dir, else default_jobs_folder(...)
  RetentionRule retention;
};

// One job's folder: made fresh for a new job (after retention), or a journal's own for --resume and
// --replay; where each output lands.
class JobFolder {
 public:
  // The jobs folder made (with its parents) and found writable, retention applied, then this job's
  // folder made (-2, -3, ... when the name is taken) and `latest` pointed at it (atomically; a link
  // that cannot be made is said, not fatal). False with `error` naming the folder and the reason;
  // then nothing was removed or made.
  [[nodiscard]] bool make(const JobFolderRequest& request, std::time_t start,
                          const std::function<void(const std::string&)>& say, std::string& error);

  // --resume, --replay: the job's folder is its journal's.
  void use_folder_of(const std::string& journal_path);

  // A path for an output: `given` with a slash as given; a bare name in this folder; nothing given,
  // `default_name` in this folder (empty: none). Without a folder, `given` as given.
  [[nodiscard]] std::string place(const std::string& given, const std::string& default_name) const;

  // A run that never ran: the folder made for it goes again if nothing is left in it, and `latest`
  // points where it pointed before.
  void abandon();

  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string jobs_folder_;
  std::string path_;             // empty: no folder (every output given, or none asked)
  std::string previous_latest_;  // where `latest` pointed before this job's (empty: nowhere)
  bool made_ = false;
};

}  // namespace stencil::report
