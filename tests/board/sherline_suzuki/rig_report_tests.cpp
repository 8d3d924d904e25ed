// The rig's report (board/sherline_suzuki/rig_report): the figures every job reports, with the
// link's last error, and the sections only the rig's run has (the first fault, the safe states, the
// resets, how long it ran), read back as JSON from a file it wrote; an unwritable path is refused.
#include <cstdio>
#include <fstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "board/sherline_suzuki/rig_report.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sherline_suzuki;

namespace {

struct TempPath {
  std::string path;
  TempPath() {
    char name[] = "/tmp/rig_report_tests_XXXXXX";
    const int fd = mkstemp(name);
    if (fd >= 0) {
      close(fd);
    }
    path = name;
  }
  ~TempPath() { std::remove(path.c_str()); }
};

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST_GROUP(RigReport){};

TEST(RigReport, HoldsTheRunsFiguresAndTheRigsOwnSections) {
  RigResult result;
  result.cycles = 1234;
  result.machine_updates = 41;
  result.machine_stop_confirmed = true;
  result.safe_state = control::SafeReason::Stopped;
  result.first_fault = control::SafeReason::PoseJump;
  result.safe_state_entries = 2;
  result.resets_accepted = 1;
  result.resets_refused = 3;
  result.run_s = 12.5;
  const TempPath file;
  std::string error;
  CHECK_TRUE(write_rig_report(file.path, result, "the CY545 did not answer", report::Provenance{}, error));
  const nlohmann::json report = read_json(file.path);
  CHECK_EQUAL(1234U, report["cycles"].get<std::uint64_t>());
  CHECK_EQUAL(41U, report["machine"]["updates"].get<std::uint64_t>());
  CHECK_TRUE(report["machine"]["stop_confirmed"].get<bool>());
  STRCMP_EQUAL("the CY545 did not answer", report["machine"]["error"].get<std::string>().c_str());
  STRCMP_EQUAL("stopped", report["safe_state"].get<std::string>().c_str());
  STRCMP_EQUAL("pose_jump", report["first_fault"].get<std::string>().c_str());
  CHECK_EQUAL(2U, report["safe_state_entries"].get<std::uint64_t>());
  CHECK_EQUAL(1U, report["resets"]["accepted"].get<std::uint64_t>());
  CHECK_EQUAL(3U, report["resets"]["refused"].get<std::uint64_t>());
  DOUBLES_EQUAL(12.5, report["run_s"].get<double>(), 0.0);
}

TEST(RigReport, NoFaultAndNoLinkErrorAreNull) {
  const TempPath file;
  std::string error;
  CHECK_TRUE(write_rig_report(file.path, RigResult{}, "", report::Provenance{}, error));
  const nlohmann::json report = read_json(file.path);
  CHECK_TRUE(report["first_fault"].is_null());
  CHECK_TRUE(report["machine"]["error"].is_null());
  CHECK_TRUE(report["safe_state"].is_null());
}

TEST(RigReport, AnUnwritablePathIsRefusedNamingIt) {
  std::string error;
  CHECK_FALSE(write_rig_report("/nonexistent-folder/report.json", RigResult{}, "", report::Provenance{}, error));
  STRCMP_CONTAINS("/nonexistent-folder/report.json", error.c_str());
}
