#include "firmware/services/report/job_folder.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <sys/stat.h>
#include <unistd.h>

#include "firmware/services/journal/journal_reader.hpp"

namespace stencil::report {
namespace {

namespace fs = std::filesystem;

bool all_digits(const std::string& text, std::size_t from, std::size_t count) {
  if (from + count > text.size()) {
    return false;
  }
  return std::all_of(text.begin() + static_cast<std::ptrdiff_t>(from),
                     text.begin() + static_cast<std::ptrdiff_t>(from + count),
                     [](char c) { return c >= '0' && c <= '9'; });
}

// "YYYYMMDD-HHMMSS" at `at`.
bool is_stamp(const std::string& name, std::size_t at) {
  return all_digits(name, at, 8) && at + 8 < name.size() && name[at + 8] == '-' && all_digits(name, at + 9, 6);
}

std::string joined(const std::string& folder, const std::string& name) {
  std::string path = folder;
  if (!path.empty() && path.back() != '/') {
    path += '/';
  }
  path.append(name);
  return path;
}

bool exists(const std::string& path) {
  struct stat info {};
  return ::lstat(path.c_str(), &info) == 0;
}

std::uint64_t folder_bytes(const std::string& folder) {
  std::uint64_t bytes = 0;
  std::error_code error;
  for (fs::recursive_directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    std::error_code size_error;
    if (it->is_regular_file(size_error)) {
      const std::uintmax_t size = it->file_size(size_error);
      bytes += size_error ? 0 : static_cast<std::uint64_t>(size);
    }
  }
  return bytes;
}

std::string megabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

// `latest` -> `target` (a name in the same folder): a link made under a name of its own, then renamed
// over the old one, so that `latest` is never missing or half made.
bool point_latest(const std::string& jobs_folder, const std::string& target, std::string& error) {
  const std::string latest = joined(jobs_folder, "latest");
  const std::string temporary = joined(jobs_folder, ".latest-" + std::to_string(::getpid()));
  static_cast<void>(::unlink(temporary.c_str()));
  if (::symlink(target.c_str(), temporary.c_str()) != 0 || ::rename(temporary.c_str(), latest.c_str()) != 0) {
    error = latest + ": cannot point at " + target + ": " + std::strerror(errno);
    static_cast<void>(::unlink(temporary.c_str()));
    return false;
  }
  return true;
}

// The folder made with its parents, and one this process may make files in.
bool prepare_jobs_folder(const std::string& jobs_folder, std::string& error) {
  std::error_code made;
  fs::create_directories(jobs_folder, made);
  if (made) {
    error = jobs_folder + ": the jobs folder cannot be created: " + made.message();
    return false;
  }
  if (!fs::is_directory(jobs_folder, made)) {
    error = jobs_folder + ": the jobs folder is not a folder";
    return false;
  }
  if (::access(jobs_folder.c_str(), W_OK | X_OK) != 0) {
    error = jobs_folder + ": the jobs folder cannot be written in: " + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace

std::string default_jobs_folder(const std::string& configured, const char* xdg_state_home, const char* home) {
  if (!configured.empty()) {
    return configured;
  }
  if (xdg_state_home != nullptr && xdg_state_home[0] == '/') {
    return joined(xdg_state_home, "stencil/jobs");
  }
  if (home != nullptr && home[0] != '\0') {
    return joined(home, ".local/state/stencil/jobs");
  }
  return "";
}

std::string job_folder_name(const std::string& program, std::time_t start) {
  std::tm local{};
  localtime_r(&start, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "-%Y%m%d-%H%M%S", &local);
  std::string name = program;
  name.append(stamp);
  return name;
}

bool parse_job_folder_name(const std::string& name, JobFolderOrder& order) {
  // The program's name: lower-case letters and dashes, ending before the stamp's dash.
  std::size_t at = 0;
  while (at < name.size() && ((name[at] >= 'a' && name[at] <= 'z') || name[at] == '-')) {
    ++at;
  }
  // The stamp starts after the last dash of that run; the program's name is not empty.
  const std::size_t dash = name.rfind('-', at == 0 ? 0 : at - 1);
  if (dash == std::string::npos || dash == 0 || dash + 1 != at || !is_stamp(name, at)) {
    return false;
  }
  order.start = name.substr(at, 15);
  order.number = 1;
  const std::size_t after = at + 15;
  if (after == name.size()) {
    return true;
  }
  // "-N", N from 2, no leading zero.
  if (name[after] != '-' || after + 1 >= name.size() || name[after + 1] == '0' ||
      !all_digits(name, after + 1, name.size() - after - 1) || name.size() - after - 1 > 6) {
    return false;
  }
  order.number = static_cast<unsigned>(std::stoul(name.substr(after + 1)));
  return order.number >= 2;
}

std::vector<JobFate> retention_fates(const std::vector<JobEntry>& oldest_first, const RetentionRule& rule) {
  std::vector<JobFate> fates(oldest_first.size(), JobFate::Kept);
  // The one starting is one of keep_jobs: the newest keep_jobs - 1 already there are within it.
  const std::size_t kept_by_count = rule.keep_jobs == 0 ? oldest_first.size() : rule.keep_jobs - 1U;
  std::uint64_t bytes = 0;
  std::size_t newer = 0;
  for (std::size_t i = oldest_first.size(); i-- > 0; ++newer) {
    bytes += oldest_first[i].bytes;
    const bool within = newer < kept_by_count && (rule.keep_bytes == 0 || bytes <= rule.keep_bytes);
    if (!within) {
      fates[i] = oldest_first[i].finished ? JobFate::Removed : JobFate::KeptInterrupted;
    }
  }
  return fates;
}

std::vector<JobEntry> list_job_folders(const std::string& jobs_folder) {
  std::vector<std::pair<JobFolderOrder, JobEntry>> found;
  std::error_code error;
  for (fs::directory_iterator it(jobs_folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    JobFolderOrder order;
    std::error_code kind_error;
    // A real folder only: a link (`latest` among them) is never a job.
    if (!parse_job_folder_name(name, order) || !it->is_directory(kind_error) || it->is_symlink(kind_error)) {
      continue;
    }
    const std::string path = joined(jobs_folder, name);
    if (!exists(joined(path, "job.journal")) && !exists(joined(path, "report.json"))) {
      continue;
    }
    found.push_back({order, {name, false, folder_bytes(path)}});
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return a.first < b.first || (!(b.first < a.first) && a.second.name < b.second.name);
  });
  std::vector<JobEntry> jobs;
  for (auto& [order, entry] : found) {
    jobs.push_back(std::move(entry));
  }
  return jobs;
}

bool job_finished(const std::string& job_folder) {
  const std::string journal_path = joined(job_folder, "job.journal");
  if (!exists(journal_path)) {
    return exists(joined(job_folder, "report.json"));
  }
  bool ended = false;
  journal::JournalVisitor visit;
  visit.start = [&ended](const journal::JournalStart&) { ended = false; };
  visit.resume = [&ended](const journal::JournalResume&) { ended = false; };
  visit.end = [&ended](std::uint64_t, control::SafeReason) { ended = true; };
  const journal::JournalReadResult read = journal::read_journal_file(journal_path, visit);
  return read.ok && ended;
}

void apply_retention(const std::string& jobs_folder, const RetentionRule& rule,
                     const std::function<void(const std::string&)>& say) {
  std::vector<JobEntry> jobs = list_job_folders(jobs_folder);
  // Every job taken as finished first: only those beyond the rule have their journals read. Whether
  // a job is finished changes only what becomes of it, not which are beyond the rule.
  for (JobEntry& job : jobs) {
    job.finished = true;
  }
  const std::vector<JobFate> beyond = retention_fates(jobs, rule);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (beyond[i] == JobFate::Kept) {
      continue;
    }
    const std::string path = joined(jobs_folder, jobs[i].name);
    if (!job_finished(path)) {
      say("jobs: kept " + path + ": interrupted, may be resumed");
      continue;
    }
    std::error_code error;
    fs::remove_all(path, error);
    say(error ? "jobs: could not remove " + path + ": " + error.message()
              : "jobs: removed " + path + " (finished, " + megabytes(jobs[i].bytes) + ")");
  }
}

bool JobFolder::make(const JobFolderRequest& request, std::time_t start,
                     const std::function<void(const std::string&)>& say, std::string& error) {
  if (request.jobs_folder.empty()) {
    error = "no folder for the job: HOME is not set (give --out-dir)";
    return false;
  }
  if (!prepare_jobs_folder(request.jobs_folder, error)) {
    return false;
  }
  apply_retention(request.jobs_folder, request.retention, say);
  const std::string name = job_folder_name(request.program, start);
  std::string chosen;
  for (unsigned number = 1; number < 1000 && chosen.empty(); ++number) {
    const std::string candidate = number == 1 ? name : name + "-" + std::to_string(number);
    const std::string path = joined(request.jobs_folder, candidate);
    if (::mkdir(path.c_str(), 0777) == 0) {
      chosen = candidate;
    } else if (errno != EEXIST) {
      error = path + ": the job's folder cannot be created: " + std::strerror(errno);
      return false;
    }
  }
  if (chosen.empty()) {
    error = joined(request.jobs_folder, name) + ": the job's folder cannot be created: 999 of that name already";
    return false;
  }
  jobs_folder_ = request.jobs_folder;
  path_ = joined(request.jobs_folder, chosen);
  made_ = true;
  std::error_code link_error;
  const fs::path previous = fs::read_symlink(joined(jobs_folder_, "latest"), link_error);
  previous_latest_ = link_error ? std::string() : previous.string();
  std::string latest_error;
  if (!point_latest(jobs_folder_, chosen, latest_error)) {
    say("jobs: " + latest_error);
  }
  return true;
}

void JobFolder::use_folder_of(const std::string& journal_path) {
  const std::size_t slash = journal_path.rfind('/');
  path_ = slash == std::string::npos ? std::string(".") : slash == 0 ? std::string("/") : journal_path.substr(0, slash);
  made_ = false;
}

std::string JobFolder::place(const std::string& given, const std::string& default_name) const {
  if (path_.empty() || given.find('/') != std::string::npos) {
    return given;
  }
  if (!given.empty()) {
    return joined(path_, given);
  }
  return default_name.empty() ? std::string() : joined(path_, default_name);
}

void JobFolder::abandon() {
  if (!made_ || ::rmdir(path_.c_str()) != 0) {
    return;
  }
  made_ = false;
  const std::string latest = joined(jobs_folder_, "latest");
  std::string error;
  if (previous_latest_.empty() || !point_latest(jobs_folder_, previous_latest_, error)) {
    static_cast<void>(::unlink(latest.c_str()));
  }
}

}  // namespace stencil::report
