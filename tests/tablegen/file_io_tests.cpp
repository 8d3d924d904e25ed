// The table generator's files (toolchain/tablegen/file_io): a regular file's size, and anything else
// (missing, a directory, a device) refused naming the path; an output that appears whole or not at
// all: nothing at the path until commit(), the previous file kept and no temporary left behind when
// abandoned, an unwritable place refused before any work is done.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "toolchain/tablegen/file_io.hpp"
#include "toolchain/tablegen/input_error.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::tablegen;

namespace {

struct TempDir {
  std::string path;
  TempDir() {
    char name[] = "/tmp/file_io_tests_XXXXXX";
    const char* made = mkdtemp(name);
    path = made != nullptr ? made : "";
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  [[nodiscard]] std::size_t entries() const {
    std::size_t n = 0;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      static_cast<void>(entry);
      ++n;
    }
    return n;
  }
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The InputError's message, or "" when none was thrown.
template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_GROUP(FileIo){};

TEST(FileIo, ARegularFilesSizeIsItsBytes) {
  const TempDir dir;
  const std::string path = dir.path + "/part.stl";
  { std::ofstream(path) << "12345"; }
  CHECK_EQUAL(5U, regular_file_size(path));
}

TEST(FileIo, WhatIsNotARegularFileIsRefusedByName) {
  const TempDir dir;
  STRCMP_EQUAL((dir.path + ": is a directory; expected a file").c_str(),
               input_error_of([&] { static_cast<void>(regular_file_size(dir.path)); }).c_str());
  STRCMP_EQUAL("/dev/null: is not a regular file",
               input_error_of([] { static_cast<void>(regular_file_size("/dev/null")); }).c_str());
  STRCMP_CONTAINS((dir.path + "/missing.stl: cannot open (").c_str(),
                  input_error_of([&] { static_cast<void>(regular_file_size(dir.path + "/missing.stl")); }).c_str());
}

TEST(FileIo, APendingFileAppearsOnlyWhenCommitted) {
  const TempDir dir;
  const std::string path = dir.path + "/table.stbl";
  {
    PendingFile out(path);
    out.write("abc", 3);
    out.write("def", 3);
    CHECK_FALSE(std::filesystem::exists(path));
    out.commit();
  }
  STRCMP_EQUAL("abcdef", read_text(path).c_str());
  CHECK_EQUAL(1U, dir.entries());  // no temporary left beside it
  CHECK_EQUAL(0644U, static_cast<unsigned>(std::filesystem::status(path).permissions() & std::filesystem::perms::mask));
}

TEST(FileIo, AnAbandonedPendingFileKeepsThePreviousOneAndLeavesNothing) {
  const TempDir dir;
  const std::string path = dir.path + "/table.stbl";
  { std::ofstream(path) << "previous"; }
  {
    PendingFile out(path);
    out.write("half", 4);
  }
  STRCMP_EQUAL("previous", read_text(path).c_str());
  CHECK_EQUAL(1U, dir.entries());
}

TEST(FileIo, AnUnwritablePlaceIsRefusedBeforeAnyWork) {
  const TempDir dir;
  STRCMP_CONTAINS("/nonexistent-folder/table.stbl: cannot write the output here (",
                  input_error_of([] { PendingFile out("/nonexistent-folder/table.stbl"); }).c_str());
  STRCMP_EQUAL((dir.path + ": is a directory; expected a file name to write").c_str(),
               input_error_of([&] { PendingFile out(dir.path); }).c_str());
}
