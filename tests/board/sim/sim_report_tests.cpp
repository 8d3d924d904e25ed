// The simulation's report (board/sim/sim_report): the JSON read back (the figures every job reports,
// and the simulation's own sections: the injected fault, the journal, the mill after the stop, null
// where nothing happened), the stock's heights as CSV one Z-map row a line, and the terminal's summary
// with the lines only some runs have. An unwritable path is refused naming it.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "board/sim/sim_report.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

struct TempPath {
  std::string path;
  TempPath() {
    char name[] = "/tmp/sim_report_tests_XXXXXX";
    const int fd = mkstemp(name);
    if (fd >= 0) {
      close(fd);
    }
    path = name;
  }
  ~TempPath() { std::remove(path.c_str()); }
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_GROUP(SimReport){};

TEST(SimReport, AQuietRunHasNullWhereNothingHappened) {
  SimResult result;
  result.cycles = 500;
  result.simulated_s = 0.5;
  const TempPath file;
  std::string error;
  CHECK_TRUE(write_report_json(file.path, result, report::Provenance{}, error));
  const nlohmann::json report = nlohmann::json::parse(read_text(file.path));
  CHECK_EQUAL(500U, report["cycles"].get<std::uint64_t>());
  CHECK_TRUE(report["fault"].is_null());
  CHECK_TRUE(report["journal"].is_null());
  CHECK_TRUE(report["machine"]["safe_state_s"].is_null());
  CHECK_TRUE(report["machine"]["stopped_s"].is_null());
  CHECK_TRUE(report["gouge"]["max_depth_mm"].is_null());  // not measured
  DOUBLES_EQUAL(0.0, report["unmachined"]["fraction"].get<double>(), 0.0);
}

TEST(SimReport, TheFaultTheJournalAndTheMillAfterTheStopAreReported) {
  SimResult result;
  result.fault_kind = FaultKind::SerialClosed;
  result.fault_injected_s = 2.0;
  result.safe_state_s = 2.1;
  result.machine_stopped_s = 2.2;
  result.journal_path = "job.journal";
  result.journal_records = 7;
  result.journal_error = "disk full";
  result.gouge_measured = true;
  result.gouge_max_depth_mm = 0.004;
  result.unmachined_volume_mm3 = 1.0;
  result.reachable_volume_mm3 = 4.0;
  result.earlier.recorded_s = 10.0;
  result.simulated_s = 3.0;
  const TempPath file;
  std::string error;
  CHECK_TRUE(write_report_json(file.path, result, report::Provenance{}, error));
  const nlohmann::json report = nlohmann::json::parse(read_text(file.path));
  STRCMP_EQUAL("serial-closed", report["fault"]["kind"].get<std::string>().c_str());
  DOUBLES_EQUAL(2.0, report["fault"]["injected_s"].get<double>(), 0.0);
  DOUBLES_EQUAL(2.1, report["machine"]["safe_state_s"].get<double>(), 0.0);
  DOUBLES_EQUAL(2.2, report["machine"]["stopped_s"].get<double>(), 0.0);
  STRCMP_EQUAL("job.journal", report["journal"]["path"].get<std::string>().c_str());
  CHECK_EQUAL(7U, report["journal"]["cycle_records"].get<std::uint64_t>());
  STRCMP_EQUAL("disk full", report["journal"]["error"].get<std::string>().c_str());
  DOUBLES_EQUAL(0.004, report["gouge"]["max_depth_mm"].get<double>(), 0.0);
  DOUBLES_EQUAL(0.25, report["unmachined"]["fraction"].get<double>(), 0.0);
  // The whole job's time: the runs before this one and this one.
  DOUBLES_EQUAL(13.0, report["job"]["total_simulated_s"].get<double>(), 0.0);
}

TEST(SimReport, AGcodeProgramsRefusedLinesAreInTheReportAndTheSummaryAndOtherwiseNothingIs) {
  const TempPath file;
  std::string error;
  SimResult plain;
  CHECK_TRUE(write_report_json(file.path, plain, report::Provenance{}, error));
  CHECK_FALSE(nlohmann::json::parse(read_text(file.path)).contains("gcode"));  // every other job's report as before
  SimResult guarded;
  guarded.gcode_program = "cam.ngc";
  guarded.gcode_refused = {{11, 0.5}, {14, 0.25}};
  CHECK_TRUE(write_report_json(file.path, guarded, report::Provenance{}, error));
  const nlohmann::json report = nlohmann::json::parse(read_text(file.path));
  STRCMP_EQUAL("operator", report["gcode"]["run"].get<std::string>().c_str());
  LONGS_EQUAL(2, report["gcode"]["refused"].size());
  LONGS_EQUAL(14, report["gcode"]["refused"][1]["line"].get<int>());
  DOUBLES_EQUAL(0.25, report["gcode"]["refused"][1]["depth_mm"].get<double>(), 0.0);
  CHECK(summary(guarded).find("gcode: 2 lines of cam.ngc refused or shortened by the stencil: line 11 (0.500 mm deep) "
                              "line 14 (0.250 mm deep)") != std::string::npos);
  guarded.gcode_direct = true;
  CHECK_TRUE(write_report_json(file.path, guarded, report::Provenance{}, error));
  CHECK_TRUE(nlohmann::json::parse(read_text(file.path))["gcode"]["refused"].is_null());
}

TEST(SimReport, TheStockCsvIsOneRowALineWithYRising) {
  SimResult result;
  result.columns = 3;
  result.rows = 2;
  result.stock_heights = {1.0, 2.0, 3.0, 4.5, 5.0, 6.25};
  const TempPath file;
  std::string error;
  CHECK_TRUE(write_stock_csv(file.path, result, error));
  STRCMP_EQUAL("1.00000,2.00000,3.00000\n4.50000,5.00000,6.25000\n", read_text(file.path).c_str());
}

TEST(SimReport, UnwritablePathsAreRefusedNamingThem) {
  std::string error;
  CHECK_FALSE(write_stock_csv("/nonexistent-folder/stock.csv", SimResult{}, error));
  STRCMP_EQUAL("/nonexistent-folder/stock.csv: cannot be written", error.c_str());
  CHECK_FALSE(write_report_json("/nonexistent-folder/report.json", SimResult{}, report::Provenance{}, error));
  STRCMP_CONTAINS("/nonexistent-folder/report.json", error.c_str());
}

TEST(SimReport, TheSummaryOfAQuietVirtualTimeRunHasNoLatencyJournalOrMachineLine) {
  SimResult result;
  result.cycles = 1000;
  result.simulated_s = 1.0;
  const std::string text = summary(result);
  STRCMP_CONTAINS("simulated 1.0 s in 0.0 s (1000 cycles, 0 machine updates)", text.c_str());
  STRCMP_CONTAINS("gouge: not measured (not a ball end mill) mm deepest", text.c_str());
  STRCMP_CONTAINS("safe state: none\n", text.c_str());
  CHECK(text.find("wake-up latency") == std::string::npos);
  CHECK(text.find("journal:") == std::string::npos);
  CHECK(text.find("machine:") == std::string::npos);
  CHECK(text.find("WARNING") == std::string::npos);
}

TEST(SimReport, TheSummaryAddsWhatOnlySomeRunsHave) {
  SimResult result;
  result.wakeup_latency_us.max = 80.0;
  result.overruns = 3;
  result.journal_error = "disk full";
  result.machine_error = "the CY545 did not answer";
  result.mill_spindle_on_after_stop = true;
  result.safe_state = control::SafeReason::MachineFault;
  const std::string text = summary(result);
  STRCMP_CONTAINS("safe state: machine_fault\n", text.c_str());
  STRCMP_CONTAINS("max 80.0 us; 3 overruns", text.c_str());
  STRCMP_CONTAINS("journal: disk full\n", text.c_str());
  STRCMP_CONTAINS("machine: the CY545 did not answer\n", text.c_str());
  STRCMP_CONTAINS("mill: WARNING after the stop the spindle was ON and the drivers off; the watchdog relay dropped them",
                  text.c_str());
}
