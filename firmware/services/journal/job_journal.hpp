// A program's journal for one run of a job: a fresh one named after the start time, or the job's
// own carried on; and, when the run never ran, the file put back as it was. Both programs open
// their journals this way, so a fresh journal, a resumed one and an unrun one mean the same in each.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "firmware/services/journal/journal_writer.hpp"

namespace stencil::journal {

struct JobJournalRequest {
  std::string program;       // "stencil-sim", "stencil-rig": the Start/Resume record's and the default name's
  std::string path;          // --journal; empty: <program>-YYYYMMDD-HHMMSS.journal in `folder`, at the start time
  std::string folder;        // the default name's folder (empty: the current one)
  bool none = false;         // --no-journal
  std::string resume_path;   // --resume: carry on in this file from its first resume_bytes
  std::size_t resume_bytes = 0;
  JournalStart start;        // a fresh journal's Start record (program and time filled in here)
  JournalResume resume;      // a resumed one's Resume record (program and time filled in here)
  std::string provenance;    // what makes this run (report::provenance_line): after its Start or Resume
};

// Opens `writer` as asked (nothing with `none`); the path it writes goes to `opened_path` (empty:
// none). False with `error` naming the file when it cannot be opened.
[[nodiscard]] bool open_job_journal(const JobJournalRequest& request, JournalWriter& writer, std::string& opened_path,
                                    std::string& error);

// A run that never ran leaves no trace: a fresh journal of nothing goes, a resumed one is cut back
// to the job it held (no Resume record of a run that never ran). False when the cut failed.
[[nodiscard]] bool undo_unrun_job_journal(const JobJournalRequest& request, JournalWriter& writer,
                                          const std::string& opened_path);

}  // namespace stencil::journal
