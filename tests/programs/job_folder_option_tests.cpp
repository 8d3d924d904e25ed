// Where a job writes (firmware/programs/job_folder_option): the configuration's retention where the
// command line gave none, and the job's own folder made under --out-dir, a refusal there naming
// --out-dir. Retention itself is report::JobFolder's (tests/report).
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include "firmware/programs/job_folder_option.hpp"
#include "tests/support/command_line.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct Parsed {
  CLI::App app;
  app::JobFolderOptions options;
  explicit Parsed(const std::vector<std::string>& words) {
    app::add_job_folder_options(app, options, "stencil-test", "its outputs", "a resume elsewhere");
    test::parse_words(app, words);
  }
};

struct TempDir {
  std::string path;
  TempDir() {
    char name[] = "/tmp/job_folder_option_tests_XXXXXX";
    const char* made = mkdtemp(name);
    path = made != nullptr ? made : "";
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace

TEST_GROUP(JobFolderOption){};

TEST(JobFolderOption, TheConfiguredRetentionFillsOnlyWhatTheCommandLineLeft) {
  Parsed none({});
  app::take_configured_retention(none.app, none.options, 7, 300);
  CHECK_EQUAL(7U, none.options.keep_jobs);
  CHECK_EQUAL(300U, none.options.keep_mb);
  Parsed given({"--keep-jobs", "3", "--keep-mb", "0"});
  app::take_configured_retention(given.app, given.options, 7, 300);
  CHECK_EQUAL(3U, given.options.keep_jobs);
  CHECK_EQUAL(0U, given.options.keep_mb);
}

TEST(JobFolderOption, CliRefusesANegativeOrHugeKeep) {
  CHECK_THROWS(CLI::ParseError, Parsed({"--keep-jobs", "-1"}));
  CHECK_THROWS(CLI::ParseError, Parsed({"--keep-jobs", "100001"}));
}

TEST(JobFolderOption, TheJobsFolderIsMadeUnderOutDirNamedForTheProgram) {
  const TempDir jobs;
  Parsed c({"--out-dir", jobs.path + "/deeper"});
  report::JobFolder folder;
  std::string error;
  std::vector<std::string> said;
  CHECK_TRUE(app::make_job_folder(c.options, "stencil-test", "/never/used", folder, [&said](const std::string& line) { said.push_back(line); }, error));
  CHECK_EQUAL(0U, folder.path().find(jobs.path + "/deeper/stencil-test-"));
  CHECK_TRUE(std::filesystem::is_directory(folder.path()));
}

TEST(JobFolderOption, AFolderThatCannotBeMadeIsNamedAsOutDirs) {
  Parsed c({"--out-dir", "/proc/no-jobs-here"});
  report::JobFolder folder;
  std::string error;
  CHECK_FALSE(app::make_job_folder(c.options, "stencil-test", "", folder, [](const std::string&) {}, error));
  CHECK_EQUAL(0U, error.find("--out-dir: "));
}

TEST(JobFolderOption, WithoutOutDirTheConfiguredFolderIsUsedAndARefusalDoesNotNameOutDir) {
  const TempDir jobs;
  Parsed c({});
  report::JobFolder folder;
  std::string error;
  CHECK_TRUE(app::make_job_folder(c.options, "stencil-test", jobs.path, folder, [](const std::string&) {}, error));
  CHECK_EQUAL(0U, folder.path().find(jobs.path + "/stencil-test-"));
  report::JobFolder refused;
  CHECK_FALSE(app::make_job_folder(c.options, "stencil-test", "/proc/no-jobs-here", refused, [](const std::string&) {}, error));
  CHECK(error.find("--out-dir") == std::string::npos);
}
