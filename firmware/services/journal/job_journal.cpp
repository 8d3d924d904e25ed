#include "firmware/services/journal/job_journal.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

#include <sys/types.h>
#include <unistd.h>

namespace stencil::journal {

bool open_job_journal(const JobJournalRequest& request, JournalWriter& writer, std::string& opened_path,
                      std::string& error) {
  opened_path.clear();
  const auto now = std::chrono::system_clock::now();
  const std::int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
  if (!request.resume_path.empty()) {
    JournalResume resume = request.resume;
    resume.unix_time_ns = now_ns;
    resume.program = request.program;
    resume.provenance = request.provenance;
    if (!writer.open_to_resume(request.resume_path, request.resume_bytes, resume)) {
      error = writer.error();
      return false;
    }
    opened_path = request.resume_path;
    return true;
  }
  if (request.none) {
    return true;
  }
  std::string path = request.path;
  if (path.empty()) {
    const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
    std::tm local{};
    localtime_r(&seconds, &local);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "-%Y%m%d-%H%M%S.journal", &local);
    path = (request.folder.empty() ? std::string() : request.folder + "/") + request.program + stamp;
  }
  JournalStart start = request.start;
  start.unix_time_ns = now_ns;
  start.program = request.program;
  start.provenance = request.provenance;
  if (!writer.open(path, start)) {
    error = writer.error();
    return false;
  }
  opened_path = path;
  return true;
}

bool undo_unrun_job_journal(const JobJournalRequest& request, JournalWriter& writer, const std::string& opened_path) {
  static_cast<void>(writer.close());
  if (request.resume_path.empty()) {
    if (!opened_path.empty()) {
      std::remove(opened_path.c_str());
    }
    return true;
  }
  return ::truncate(request.resume_path.c_str(), static_cast<off_t>(request.resume_bytes)) == 0;
}

}  // namespace stencil::journal
