// A job's own folder: the jobs folder's default (the XDG rule), the folder's name and order, making
// it (with `latest`), where outputs land, and retention: the decision alone, then on real folders.
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "firmware/services/journal/journal_writer.hpp"
#include "firmware/services/report/job_folder.hpp"

// Last: its memory-leak macros redefine new.
#include "CppUTest/TestHarness.h"

using namespace stencil;
using report::JobEntry;
using report::JobFate;

namespace {

namespace fs = std::filesystem;

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A journal of one run: with its End record (the run ended in order) or without (killed).
void write_journal(const std::string& path, bool ended) {
  journal::JournalWriter writer;
  journal::JournalStart start;
  start.program = "stencil-sim";
  start.job = "test job";
  CHECK_TRUE(writer.open(path, start));
  if (ended) {
    CHECK_TRUE(writer.append_end(0, control::SafeReason::None));
  }
  CHECK_TRUE(writer.close());
}

std::time_t local_time(int year, int month, int day, int hour, int minute, int second) {
  std::tm local{};
  local.tm_year = year - 1900;
  local.tm_mon = month - 1;
  local.tm_mday = day;
  local.tm_hour = hour;
  local.tm_min = minute;
  local.tm_sec = second;
  local.tm_isdst = -1;
  return std::mktime(&local);
}

std::vector<JobFate> fates_of(const std::vector<JobEntry>& jobs, unsigned keep_jobs, std::uint64_t keep_bytes) {
  return report::retention_fates(jobs, {keep_jobs, keep_bytes});
}

}  // namespace

TEST_GROUP(JobFolderNames){};

TEST(JobFolderNames, TheConfiguredFolderComesFirst) {
  STRCMP_EQUAL("/var/lib/stencil/jobs", report::default_jobs_folder("/var/lib/stencil/jobs", "/state", "/home/m").c_str());
}

TEST(JobFolderNames, XdgStateHomeWhenAbsoluteElseTheHomesLocalState) {
  STRCMP_EQUAL("/state/stencil/jobs", report::default_jobs_folder("", "/state", "/home/m").c_str());
  STRCMP_EQUAL("/home/m/.local/state/stencil/jobs", report::default_jobs_folder("", nullptr, "/home/m").c_str());
  STRCMP_EQUAL("/home/m/.local/state/stencil/jobs", report::default_jobs_folder("", "", "/home/m").c_str());
  STRCMP_EQUAL("/home/m/.local/state/stencil/jobs", report::default_jobs_folder("", "relative/state", "/home/m").c_str());
  STRCMP_EQUAL("", report::default_jobs_folder("", nullptr, nullptr).c_str());
}

TEST(JobFolderNames, NamedAfterTheProgramAndTheLocalStartTime) {
  STRCMP_EQUAL("stencil-sim-20261203-091502",
               report::job_folder_name("stencil-sim", local_time(2026, 12, 3, 9, 15, 2)).c_str());
}

TEST(JobFolderNames, ReadsAJobFoldersNameAndRefusesOthers) {
  report::JobFolderOrder order;
  CHECK_TRUE(report::parse_job_folder_name("stencil-sim-20261203-091502", order));
  STRCMP_EQUAL("20261203-091502", order.start.c_str());
  LONGS_EQUAL(1, order.number);
  CHECK_TRUE(report::parse_job_folder_name("stencil-rig-20261203-091502-12", order));
  LONGS_EQUAL(12, order.number);
  for (const char* other : {"latest", "stencil-sim-20261203", "stencil-sim-20261203-0915", "-20261203-091502",
                            "stencil-sim20261203-091502", "stencil-sim-20261203-091502-", "stencil-sim-20261203-091502-1",
                            "stencil-sim-20261203-091502-02", "stencil-sim-20261203-091502.journal",
                            "Stencil-20261203-091502", "stencil-sim-2026x203-091502"}) {
    CHECK_FALSE_TEXT(report::parse_job_folder_name(other, order), other);
  }
}

TEST(JobFolderNames, ASecondJobOfTheSameSecondSortsAfterTheFirstByNumber) {
  report::JobFolderOrder first, second, tenth, later;
  CHECK_TRUE(report::parse_job_folder_name("stencil-sim-20261203-091502", first));
  CHECK_TRUE(report::parse_job_folder_name("stencil-sim-20261203-091502-2", second));
  CHECK_TRUE(report::parse_job_folder_name("stencil-sim-20261203-091502-10", tenth));
  CHECK_TRUE(report::parse_job_folder_name("stencil-sim-20261203-091503", later));
  CHECK_TRUE(first < second);
  CHECK_TRUE(second < tenth);
  CHECK_TRUE(tenth < later);
}

TEST_GROUP(RetentionFates){};

TEST(RetentionFates, KeepsTheNewestJobsCountingTheOneStarting) {
  const std::vector<JobEntry> jobs = {{"a", true, 1}, {"b", true, 1}, {"c", true, 1}, {"d", true, 1}};
  const std::vector<JobFate> fates = fates_of(jobs, 3, 0);
  CHECK(fates == std::vector<JobFate>({JobFate::Removed, JobFate::Removed, JobFate::Kept, JobFate::Kept}));
}

TEST(RetentionFates, NeverRemovesAJobThatMayStillBeResumed) {
  const std::vector<JobEntry> jobs = {{"a", false, 1}, {"b", true, 1}, {"c", true, 1}};
  const std::vector<JobFate> fates = fates_of(jobs, 1, 0);
  CHECK(fates == std::vector<JobFate>({JobFate::KeptInterrupted, JobFate::Removed, JobFate::Removed}));
}

TEST(RetentionFates, AnInterruptedJobTakesItsPlaceAmongTheKept) {
  const std::vector<JobEntry> jobs = {{"a", true, 1}, {"b", false, 1}, {"c", true, 1}};
  const std::vector<JobFate> fates = fates_of(jobs, 3, 0);
  CHECK(fates == std::vector<JobFate>({JobFate::Removed, JobFate::Kept, JobFate::Kept}));
}

TEST(RetentionFates, ASizeCapKeepsTheNewestThatFitAndNothingOlder) {
  const std::vector<JobEntry> jobs = {{"a", true, 10}, {"b", true, 1}, {"c", true, 60}, {"d", true, 40}};
  const std::vector<JobFate> fates = fates_of(jobs, 0, 100);
  CHECK(fates == std::vector<JobFate>({JobFate::Removed, JobFate::Removed, JobFate::Kept, JobFate::Kept}));
}

TEST(RetentionFates, ZeroKeepsEveryJob) {
  const std::vector<JobEntry> jobs = {{"a", true, 1000}, {"b", true, 1000}};
  const std::vector<JobFate> fates = fates_of(jobs, 0, 0);
  CHECK(fates == std::vector<JobFate>({JobFate::Kept, JobFate::Kept}));
  CHECK_TRUE(fates_of({}, 1, 1).empty());
}

TEST_GROUP(JobFolderOnDisk) {
  std::string root;
  std::vector<std::string> said;
  std::function<void(const std::string&)> say = [this](const std::string& line) { said.push_back(line); };

  void setup() override {
    char pattern[] = "/tmp/job_folder_tests.XXXXXX";
    CHECK_TRUE(::mkdtemp(pattern) != nullptr);
    root = pattern;
  }
  void teardown() override {
    std::error_code ignored;
    fs::remove_all(root, ignored);
  }
  std::string job(const std::string& name, const std::string& journal, const std::string& report) {
    const std::string path = root + "/jobs/" + name;
    fs::create_directories(path);
    if (journal == "ended" || journal == "killed") {
      write_journal(path + "/job.journal", journal == "ended");
    } else if (!journal.empty()) {
      write_file(path + "/job.journal", journal);
    }
    if (!report.empty()) {
      write_file(path + "/report.json", report);
    }
    return path;
  }
};

TEST(JobFolderOnDisk, MakesTheJobsFolderWithItsParentsTheJobsOwnAndLatest) {
  report::JobFolder folder;
  std::string error;
  const std::time_t start = local_time(2026, 12, 3, 9, 15, 2);
  CHECK_TRUE_TEXT(folder.make({"stencil-sim", root + "/a/b/jobs", {}}, start, say, error), error.c_str());
  STRCMP_EQUAL((root + "/a/b/jobs/stencil-sim-20261203-091502").c_str(), folder.path().c_str());
  CHECK_TRUE(fs::is_directory(folder.path()));
  STRCMP_EQUAL("stencil-sim-20261203-091502", fs::read_symlink(root + "/a/b/jobs/latest").string().c_str());
  report::JobFolder second;
  CHECK_TRUE_TEXT(second.make({"stencil-sim", root + "/a/b/jobs", {}}, start, say, error), error.c_str());
  STRCMP_EQUAL((root + "/a/b/jobs/stencil-sim-20261203-091502-2").c_str(), second.path().c_str());
  STRCMP_EQUAL("stencil-sim-20261203-091502-2", fs::read_symlink(root + "/a/b/jobs/latest").string().c_str());
  CHECK_TRUE(said.empty());
}

TEST(JobFolderOnDisk, AJobsFolderThatCannotBeMadeIsRefusedNamingItAndWhy) {
  write_file(root + "/a_file", "");
  report::JobFolder folder;
  std::string error;
  CHECK_FALSE(folder.make({"stencil-sim", root + "/a_file/jobs", {}}, std::time(nullptr), say, error));
  STRCMP_CONTAINS((root + "/a_file/jobs: the jobs folder cannot be created: Not a directory").c_str(), error.c_str());
  CHECK_FALSE(folder.make({"stencil-sim", "", {}}, std::time(nullptr), say, error));
  STRCMP_CONTAINS("HOME is not set", error.c_str());
}

TEST(JobFolderOnDisk, OutputsLandInTheFolderUnlessGivenWithASlash) {
  report::JobFolder folder;
  STRCMP_EQUAL("trace.csv", folder.place("trace.csv", "").c_str());
  STRCMP_EQUAL("", folder.place("", "report.json").c_str());
  folder.use_folder_of(root + "/jobs/stencil-sim-20261203-091502/job.journal");
  const std::string job_path = root + "/jobs/stencil-sim-20261203-091502";
  STRCMP_EQUAL(job_path.c_str(), folder.path().c_str());
  STRCMP_EQUAL((job_path + "/trace.csv").c_str(), folder.place("trace.csv", "").c_str());
  STRCMP_EQUAL("./trace.csv", folder.place("./trace.csv", "").c_str());
  STRCMP_EQUAL((job_path + "/report-resume-1.json").c_str(), folder.place("", "report-resume-1.json").c_str());
  STRCMP_EQUAL("", folder.place("", "").c_str());
  folder.use_folder_of("job.journal");
  STRCMP_EQUAL("./replay.json", folder.place("", "replay.json").c_str());
}

TEST(JobFolderOnDisk, AnAbandonedJobLeavesNoFolderAndLatestWhereItWas) {
  report::JobFolder first, second;
  std::string error;
  CHECK_TRUE(first.make({"stencil-sim", root + "/jobs", {}}, local_time(2026, 12, 3, 9, 0, 0), say, error));
  CHECK_TRUE(second.make({"stencil-sim", root + "/jobs", {}}, local_time(2026, 12, 3, 10, 0, 0), say, error));
  second.abandon();
  CHECK_FALSE(fs::exists(second.path()));
  STRCMP_EQUAL("stencil-sim-20261203-090000", fs::read_symlink(root + "/jobs/latest").string().c_str());
}

TEST(JobFolderOnDisk, AJobEndedWhenItsJournalsLastRunHasAnEnd) {
  CHECK_TRUE(report::job_finished(job("stencil-sim-20261203-090000", "ended", "")));
  CHECK_FALSE(report::job_finished(job("stencil-sim-20261203-090001", "killed", "{}")));
  CHECK_FALSE(report::job_finished(job("stencil-sim-20261203-090002", "not a journal", "{}")));
  CHECK_TRUE(report::job_finished(job("stencil-sim-20261203-090003", "", "{}")));
}

TEST(JobFolderOnDisk, ListsOnlyJobFoldersOldestFirst) {
  job("stencil-sim-20261203-100000", "ended", "");
  job("stencil-sim-20261203-090000-2", "", "{}");
  job("stencil-rig-20261203-090000", "", "{}");
  job("stencil-sim-20261203-080000", "", "");  // nothing of a job in it
  job("notes", "", "{}");
  fs::create_directory_symlink("stencil-sim-20261203-100000", root + "/jobs/latest");
  const std::vector<JobEntry> jobs = report::list_job_folders(root + "/jobs");
  LONGS_EQUAL(3, jobs.size());
  STRCMP_EQUAL("stencil-rig-20261203-090000", jobs[0].name.c_str());
  STRCMP_EQUAL("stencil-sim-20261203-090000-2", jobs[1].name.c_str());
  STRCMP_EQUAL("stencil-sim-20261203-100000", jobs[2].name.c_str());
  LONGS_EQUAL(2, jobs[1].bytes);
}

TEST(JobFolderOnDisk, RetentionRemovesTheOldestFinishedAndKeepsAnInterruptedOne) {
  const std::string oldest = job("stencil-sim-20261203-090000", "ended", "{}");
  const std::string killed = job("stencil-sim-20261203-090100", "killed", "{}");
  const std::string newer = job("stencil-sim-20261203-090200", "ended", "{}");
  report::JobFolder folder;
  std::string error;
  CHECK_TRUE(folder.make({"stencil-sim", root + "/jobs", {2, 0}}, local_time(2026, 12, 3, 9, 3, 0), say, error));
  CHECK_FALSE(fs::exists(oldest));
  CHECK_TRUE(fs::exists(killed));
  CHECK_TRUE(fs::exists(newer));
  LONGS_EQUAL(2, said.size());
  STRCMP_CONTAINS(("jobs: removed " + oldest + " (finished, ").c_str(), said[0].c_str());
  STRCMP_EQUAL(("jobs: kept " + killed + ": interrupted, may be resumed").c_str(), said[1].c_str());
}
