// open_job_journal and undo_unrun_job_journal (job_journal.hpp): a fresh journal named after its
// program and start time in its folder (or the path asked), none with --no-journal, the job's own
// carried on with --resume (which wins over both), the Start or Resume record stamped with the
// program, the time and the provenance; and a run that never ran leaving no trace. Against real
// files in a folder of their own, read back through the real reader.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "firmware/services/journal/job_journal.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/journal_fixtures.hpp"
#include "tests/support/temp_folder.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil::journal;
using namespace stencil::testing;

namespace {

// The files in `folder`, by name.
std::vector<std::string> files_in(const TempFolder& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder.dir)) {
    names.push_back(entry.path().filename().string());
  }
  return names;
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

JobJournalRequest request_for(const std::string& program) {
  JobJournalRequest request;
  request.program = program;
  request.start = start_of();
  request.start.program = "not this one";  // the request's program is the one written
  request.provenance = program + " v1; command: " + program;
  return request;
}

}  // namespace

TEST_GROUP(JobJournal){};

TEST(JobJournal, AFreshJournalIsNamedAfterItsProgramAndStartTimeInItsFolderAndItsStartSaysSo) {
  TempFolder folder("job_journal_tests");
  JobJournalRequest request = request_for("stencil-sim");
  request.folder = folder.path();
  JournalWriter writer;
  std::string opened;
  std::string error;
  const std::int64_t before = now_ns();
  CHECK_TEXT(open_job_journal(request, writer, opened, error), error.c_str());
  const std::int64_t after = now_ns();
  CHECK_TRUE(writer.is_open());
  CHECK_TRUE(writer.close());
  // stencil-sim-YYYYMMDD-HHMMSS.journal
  const std::string prefix = folder.path() + "/stencil-sim-";
  STRCMP_EQUAL(prefix.c_str(), opened.substr(0, prefix.size()).c_str());
  LONGS_EQUAL(prefix.size() + 8 + 1 + 6 + 8, opened.size());
  CHECK_EQUAL('-', opened[prefix.size() + 8]);
  STRCMP_EQUAL(".journal", opened.substr(opened.size() - 8).c_str());
  LONGS_EQUAL(1, files_in(folder).size());
  Seen seen;
  const JournalReadResult read = read_journal_file(opened, seen.visitor());
  CHECK_TEXT(read.ok, read.error.c_str());
  LONGS_EQUAL(1, seen.starts);
  STRCMP_EQUAL("stencil-sim", seen.start.program.c_str());
  STRCMP_EQUAL("pattern=raster seed=1", seen.start.job.c_str());
  LONGS_EQUAL(0xdeadbeef, seen.start.tables_crc32);
  CHECK(seen.start.unix_time_ns >= before && seen.start.unix_time_ns <= after);
  LONGS_EQUAL(1, seen.provenances.size());
  STRCMP_EQUAL("stencil-sim v1; command: stencil-sim", seen.provenances[0].c_str());
}

TEST(JobJournal, APathAskedForIsTheOneWrittenAndNoJournalOpensNothing) {
  TempFolder folder("job_journal_tests");
  JobJournalRequest request = request_for("stencil-rig");
  request.folder = "/nonexistent";  // only the default name's
  request.path = folder.path() + "/mine.journal";
  JournalWriter writer;
  std::string opened = "stale";
  std::string error;
  CHECK_TEXT(open_job_journal(request, writer, opened, error), error.c_str());
  STRCMP_EQUAL(request.path.c_str(), opened.c_str());
  CHECK_TRUE(writer.close());
  CHECK_TRUE(read_journal_file(request.path, {}).ok);

  JobJournalRequest none = request_for("stencil-rig");
  none.none = true;
  none.folder = folder.path();
  JournalWriter unopened;
  opened = "stale";
  CHECK_TRUE(open_job_journal(none, unopened, opened, error));
  CHECK_TRUE(opened.empty());
  CHECK_FALSE(unopened.is_open());
  LONGS_EQUAL(1, files_in(folder).size());  // mine.journal only
}

TEST(JobJournal, AJournalThatCannotBeCreatedIsAnErrorNamingItAndNoPath) {
  JobJournalRequest request = request_for("stencil-sim");
  request.folder = "/nonexistent/jobs";
  JournalWriter writer;
  std::string opened = "stale";
  std::string error;
  CHECK_FALSE(open_job_journal(request, writer, opened, error));
  CHECK_TRUE(opened.empty());
  STRCMP_CONTAINS("/nonexistent/jobs/stencil-sim-", error.c_str());
  STRCMP_CONTAINS(".journal: cannot be created: No such file or directory", error.c_str());
}

// --resume wins over --no-journal and --journal: the job's own file goes on, its Resume record
// stamped with this program, the time and what made this run.
TEST(JobJournal, AResumedJournalCarriesOnInTheJobsOwnFileWhateverElseWasAsked) {
  TempJournal file;
  write_job(file.path, 3);
  const std::size_t job_bytes = file.bytes().size();
  JobJournalRequest request = request_for("stencil-sim");
  request.none = true;
  request.path = "/nonexistent/other.journal";
  request.resume_path = file.path;
  request.resume_bytes = job_bytes;
  request.resume.segment = 2;
  request.resume.script_s = 4.5;
  request.resume.program = "not this one";
  JournalWriter writer;
  std::string opened;
  std::string error;
  const std::int64_t before = now_ns();
  CHECK_TEXT(open_job_journal(request, writer, opened, error), error.c_str());
  STRCMP_EQUAL(file.path.c_str(), opened.c_str());
  CHECK_TRUE(writer.close());
  Seen seen;
  CHECK_TRUE(read_journal_file(file.path, seen.visitor()).ok);
  LONGS_EQUAL(3, seen.cycles.size());
  LONGS_EQUAL(1, seen.resumes.size());
  LONGS_EQUAL(2, seen.resumes[0].segment);
  DOUBLES_EQUAL(4.5, seen.resumes[0].script_s, 0.0);
  STRCMP_EQUAL("stencil-sim", seen.resumes[0].program.c_str());
  CHECK(seen.resumes[0].unix_time_ns >= before);
  LONGS_EQUAL(1, seen.provenances.size());  // the resumed run's (the first had none)
  STRCMP_EQUAL("stencil-sim v1; command: stencil-sim", seen.provenances[0].c_str());

  JobJournalRequest missing = request;
  missing.resume_path = "/nonexistent/job.journal";
  JournalWriter refused;
  opened = "stale";
  CHECK_FALSE(open_job_journal(missing, refused, opened, error));
  CHECK_TRUE(opened.empty());
  STRCMP_CONTAINS("/nonexistent/job.journal", error.c_str());
}

TEST(JobJournal, AFreshRunThatNeverRanLeavesNoFile) {
  TempFolder folder("job_journal_tests");
  JobJournalRequest request = request_for("stencil-sim");
  request.folder = folder.path();
  JournalWriter writer;
  std::string opened;
  std::string error;
  CHECK_TEXT(open_job_journal(request, writer, opened, error), error.c_str());
  LONGS_EQUAL(1, files_in(folder).size());
  CHECK_TRUE(undo_unrun_job_journal(request, writer, opened));
  CHECK_FALSE(writer.is_open());
  LONGS_EQUAL(0, files_in(folder).size());
  // Nothing opened (--no-journal): nothing to undo.
  JobJournalRequest none = request;
  none.none = true;
  JournalWriter unopened;
  CHECK_TRUE(undo_unrun_job_journal(none, unopened, ""));
}

// No Resume record of a run that never ran: the file is the job it held, byte for byte.
TEST(JobJournal, AResumedRunThatNeverRanCutsTheFileBackToTheJobItHeld) {
  TempJournal file;
  write_job(file.path, 3);
  const std::vector<std::uint8_t> job = file.bytes();
  JobJournalRequest request = request_for("stencil-rig");
  request.resume_path = file.path;
  request.resume_bytes = job.size();
  request.resume.segment = 1;
  JournalWriter writer;
  std::string opened;
  std::string error;
  CHECK_TEXT(open_job_journal(request, writer, opened, error), error.c_str());
  CHECK(file.bytes().size() > job.size());  // the Resume record is in
  CHECK_TRUE(undo_unrun_job_journal(request, writer, opened));
  CHECK(job == file.bytes());
  // A cut that cannot be made says so.
  JobJournalRequest gone = request;
  gone.resume_path = "/nonexistent/job.journal";
  JournalWriter unopened;
  CHECK_FALSE(undo_unrun_job_journal(gone, unopened, ""));
}
