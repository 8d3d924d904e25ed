// The one report writer: the figures every job has, a board's sections merged in at any depth with
// their nulls kept, and the rig's report through it.
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "board/sherline_suzuki/rig_report.hpp"
#include "firmware/services/report/build_version.hpp"
#include "firmware/services/report/job_report.hpp"

// Last: its memory-leak macros redefine new.
#include "CppUTest/TestHarness.h"

using namespace stencil;

namespace {

nlohmann::json read_back(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST_GROUP(JobReport) {
  std::string path = "job_report_tests.json";
  void teardown() override { std::remove(path.c_str()); }
};

TEST(JobReport, BoardSectionsAddKeysAtAnyDepthAndKeepTheirNulls) {
  report::JobFigures figures;
  figures.cycles = 1234;
  figures.machine_updates = 41;
  figures.safe_state = control::SafeReason::PoseJump;
  const nlohmann::json board = {{"machine", {{"take_ups", 3}}}, {"fault", nullptr}, {"job", {{"total_simulated_s", 1.5}}}};
  std::string error;
  CHECK_TRUE(report::write_job_report(path, figures, board, error));
  const nlohmann::json written = read_back(path);
  CHECK_EQUAL(1234U, written["cycles"].get<unsigned>());
  CHECK_EQUAL(41U, written["machine"]["updates"].get<unsigned>());  // the figures' key kept beside the board's
  CHECK_EQUAL(3, written["machine"]["take_ups"].get<int>());
  CHECK_TRUE(written.contains("fault"));  // a null is written as null, not dropped
  CHECK_TRUE(written["fault"].is_null());
  CHECK_EQUAL(1, written["job"]["runs"].get<int>());
  DOUBLES_EQUAL(1.5, written["job"]["total_simulated_s"].get<double>(), 0.0);
  STRCMP_EQUAL("pose_jump", written["safe_state"].get<std::string>().c_str());
  // This run's safe state is the job's last.
  CHECK_EQUAL(1U, written["job"]["safe_states"].size());
}

TEST(JobReport, AnUnwritablePathIsAnErrorNamingIt) {
  std::string error;
  CHECK_FALSE(report::write_job_report("/nonexistent-folder/report.json", {}, nlohmann::json::object(), error));
  STRCMP_CONTAINS("/nonexistent-folder/report.json", error.c_str());
}

TEST(JobReport, TheRigsReportHasTheFiguresAndItsFaultsAndResets) {
  board::sherline_suzuki::RigResult result;
  result.cycles = 5000;
  result.safe_state = control::SafeReason::Stopped;
  result.first_fault = control::SafeReason::DeviceFault;
  result.resets_accepted = 2;
  result.resets_refused = 1;
  result.run_s = 5.0;
  result.wakeup_latency_us = {10.0, 20.0, 30.0, 40.0};
  result.earlier.segments = 1;
  result.earlier.cycles = 700;
  report::Provenance provenance;
  provenance.program = "stencil-rig";
  provenance.command_line = {"stencil-rig", "--config", "/etc/stencil/rig.toml", "--tables", "my part.stbl"};
  provenance.configuration = "/etc/stencil/rig.toml";
  provenance.configuration_crc32 = 0x1a2b3c4dU;
  provenance.tables = "my part.stbl";
  provenance.tables_crc32 = 0xdeadbeefU;
  provenance.triangle_count = 24;
  std::string error;
  CHECK_TRUE(board::sherline_suzuki::write_rig_report(path, result, "no reply to '? B'", provenance, error));
  const nlohmann::json written = read_back(path);
  STRCMP_EQUAL("device_fault", written["first_fault"].get<std::string>().c_str());
  STRCMP_EQUAL("stopped", written["safe_state"].get<std::string>().c_str());
  CHECK_EQUAL(2, written["resets"]["accepted"].get<int>());
  CHECK_EQUAL(1, written["resets"]["refused"].get<int>());
  DOUBLES_EQUAL(30.0, written["wakeup_latency_us"]["p999"].get<double>(), 0.0);
  CHECK_EQUAL(2, written["job"]["runs"].get<int>());
  CHECK_EQUAL(5700, written["job"]["total_cycles"].get<int>());
  STRCMP_EQUAL("no reply to '? B'", written["machine"]["error"].get<std::string>().c_str());
  // What made it: the build, the command line, the configuration's digest and the tables' identity.
  const nlohmann::json& made = written["provenance"];
  STRCMP_EQUAL("stencil-rig", made["program"].get<std::string>().c_str());
  STRCMP_EQUAL(report::source_version(), made["version"].get<std::string>().c_str());
  STRCMP_EQUAL(report::build_compiler(), made["compiler"].get<std::string>().c_str());
  STRCMP_EQUAL("my part.stbl", made["command_line"][4].get<std::string>().c_str());
  STRCMP_EQUAL("1a2b3c4d", made["configuration"]["crc32"].get<std::string>().c_str());
  STRCMP_EQUAL("/etc/stencil/rig.toml", made["configuration"]["path"].get<std::string>().c_str());
  STRCMP_EQUAL("deadbeef", made["tables"]["crc32"].get<std::string>().c_str());
  CHECK_EQUAL(24, made["tables"]["triangles"].get<int>());
}
