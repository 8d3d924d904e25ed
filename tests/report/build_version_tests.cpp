// What built a program (build_version.hpp): --version's text is the program and the source's version
// on one line and the compiler and its flags on the next; the compiler recorded is the one that built
// this very test, the flags its build type's, and the version one word (git describe's, or the note
// that there was no checkout). Against the values the build wrote for this build.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>

#include "firmware/services/report/build_version.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::report;

namespace {

// As CMake names this compiler: CMAKE_CXX_COMPILER_ID and CMAKE_CXX_COMPILER_VERSION.
std::string this_compiler() {
#if defined(__clang__)
  return "Clang " + std::to_string(__clang_major__) + "." + std::to_string(__clang_minor__) + "." +
         std::to_string(__clang_patchlevel__);
#elif defined(__GNUC__)
  return "GNU " + std::to_string(__GNUC__) + "." + std::to_string(__GNUC_MINOR__) + "." +
         std::to_string(__GNUC_PATCHLEVEL__);
#else
  return build_compiler();
#endif
}

}  // namespace

TEST_GROUP(BuildVersion){};

TEST(BuildVersion, TheVersionTextIsTheProgramAndVersionThenTheCompilerAndFlags) {
  const std::string text = version_text("stencil-sim");
  const std::string want = std::string("stencil-sim ") + source_version() + "\nbuilt with " + build_compiler() + ": " +
                           build_flags();
  STRCMP_EQUAL(want.c_str(), text.c_str());
  // Two lines exactly: the first is what scripts read.
  LONGS_EQUAL(1, std::count(text.begin(), text.end(), '\n'));
  STRCMP_EQUAL((std::string("stencil-sim ") + source_version()).c_str(), text.substr(0, text.find('\n')).c_str());
}

TEST(BuildVersion, TheRecordedCompilerIsTheOneThatBuiltThisAndTheFlagsAreItsBuildTypes) {
  STRCMP_EQUAL(this_compiler().c_str(), build_compiler());
  const std::string flags = build_flags();
  CHECK(flags.find('\n') == std::string::npos);
#ifdef NDEBUG
  STRCMP_CONTAINS("-DNDEBUG", flags.c_str());
#else
  CHECK(flags.find("-DNDEBUG") == std::string::npos);
#endif
}

// git describe --always --dirty --tags gives one word ("v0.3-12-gabc1234-dirty", "5adf8a5"); without
// a checkout the build says so rather than leave it empty.
TEST(BuildVersion, TheSourceVersionIsGitsWordOrSaysThereWasNoCheckout) {
  const std::string version = source_version();
  CHECK_FALSE(version.empty());
  if (version == "unknown (built outside a git checkout)") {
    return;
  }
  for (const char c : version) {
    CHECK_TEXT(std::isalnum(static_cast<unsigned char>(c)) != 0 || std::strchr("._-+", c) != nullptr, version.c_str());
  }
}
