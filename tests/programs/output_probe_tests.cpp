// Whether an output can be written, found out before the job (firmware/programs/output_probe): a
// file made only to find out is removed again, one that was there is left as it was, and a place
// that cannot be written is named.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "firmware/programs/output_probe.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

TEST_GROUP(OutputProbe){};

TEST(OutputProbe, ANewFileIsFoundWritableAndNotLeftBehind) {
  const std::string path = "/tmp/output_probe_tests_" + std::to_string(getpid()) + ".json";
  std::string error;
  CHECK_TRUE(app::probe_writable(path, error));
  CHECK_EQUAL(-1, access(path.c_str(), F_OK));
}

TEST(OutputProbe, AnExistingFileIsLeftAsItWas) {
  const std::string path = "/tmp/output_probe_tests_kept_" + std::to_string(getpid()) + ".json";
  { std::ofstream(path) << "earlier job\n"; }
  std::string error;
  CHECK_TRUE(app::probe_writable(path, error));
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  STRCMP_EQUAL("earlier job\n", text.str().c_str());
  std::remove(path.c_str());
}

TEST(OutputProbe, APlaceThatCannotBeWrittenIsNamed) {
  std::string error;
  CHECK_FALSE(app::probe_writable("/nonexistent-folder/report.json", error));
  STRCMP_EQUAL("/nonexistent-folder/report.json: cannot be written", error.c_str());
  CHECK_FALSE(app::probe_writable("/tmp", error));  // a directory
}
