// Where a program finds what ships beside it (installed_files.hpp): under <prefix>/share/stencil when
// installed, else in its build tree, never the current folder; and "sample:NAME" as a shipped sample
// part, refused with the names there are. This test runs from <build>/bin, so its prefix is the build
// folder: what exists there decides, as it does for the programs.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "firmware/services/report/installed_files.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::report;
namespace fs = std::filesystem;

namespace {

// <prefix>: the folder above the one this test runs from.
fs::path prefix() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path(); }

// The sample parts shipped in `folder` (none when it is missing).
std::vector<std::string> stl_names(const std::string& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() == ".stl") {
      names.push_back(entry.path().stem().string());
    }
  }
  return names;
}

}  // namespace

TEST_GROUP(InstalledFiles){};

TEST(InstalledFiles, TheBuildTreesFileIsFoundWhenNothingIsInstalledAndTheInstalledPathNamedWhenNeitherIs) {
  // <build>/bin exists (this test is in it); <build>/share/stencil/... does not.
  STRCMP_EQUAL((prefix() / "bin").string().c_str(), shipped_path("nothing-installed", "bin").c_str());
  STRCMP_EQUAL((prefix() / "share" / "stencil" / "nothing-installed").string().c_str(),
               shipped_path("nothing-installed", "nothing-built").c_str());
  STRCMP_EQUAL(shipped_path("page", "hmi").c_str(), page_folder().c_str());
}

// The current folder is never looked in: a file of that name there changes nothing.
TEST(InstalledFiles, TheCurrentFolderIsNeverLookedIn) {
  const fs::path here = fs::current_path();
  const fs::path elsewhere = fs::temp_directory_path();
  const std::string name = "installed-files-tests-" + std::to_string(getpid());
  fs::create_directories(elsewhere / name / "stencil");
  fs::current_path(elsewhere);
  const std::string found = shipped_path(name, name);
  fs::current_path(here);
  fs::remove_all(elsewhere / name);
  STRCMP_EQUAL((prefix() / "share" / "stencil" / name).string().c_str(), found.c_str());
}

TEST(InstalledFiles, ASamplePartIsTheShippedFileAndAnythingElseIsLeftAsItIs) {
  std::string error;
  STRCMP_EQUAL("my part.stl", resolve_sample_part("my part.stl", error).c_str());
  STRCMP_EQUAL("samples:x", resolve_sample_part("samples:x", error).c_str());
  CHECK_TRUE(error.empty());
  const std::string folder = shipped_path("parts", "parts");
  const std::vector<std::string> names = stl_names(folder);
  for (const std::string& name : names) {
    error.clear();
    STRCMP_EQUAL((fs::path(folder) / (name + ".stl")).string().c_str(), resolve_sample_part("sample:" + name, error).c_str());
    CHECK_TRUE(error.empty());
  }
}

// Only a name: a path is refused even where it would lead to a part, and the error lists the parts.
TEST(InstalledFiles, AnUnknownSamplePartOrAPathIsRefusedListingThePartsThereAre) {
  const std::string folder = shipped_path("parts", "parts");
  const std::vector<std::string> names = stl_names(folder);
  std::string error;
  STRCMP_EQUAL("", resolve_sample_part("sample:no-such-part", error).c_str());
  STRCMP_CONTAINS(("sample:no-such-part: no such sample part in " + folder + " (expected sample:NAME with NAME one of ").c_str(),
                  error.c_str());
  if (names.empty()) {
    STRCMP_CONTAINS("none: the folder is missing)", error.c_str());
  }
  for (const std::string& name : names) {
    STRCMP_CONTAINS(name.c_str(), error.c_str());
  }
  error.clear();
  const std::string through = "sample:../parts/" + (names.empty() ? std::string("x") : names[0]);
  STRCMP_EQUAL("", resolve_sample_part(through, error).c_str());
  STRCMP_CONTAINS("no such sample part", error.c_str());
  error.clear();
  STRCMP_EQUAL("", resolve_sample_part("sample:", error).c_str());
  STRCMP_CONTAINS("sample:: no such sample part", error.c_str());
}
