// stencil-rig's command line (firmware/programs/rig_options): the configuration file under the
// command line's overrides and what a job requires (apply_rig_config), then the work offset, the
// stock and the haptic link read and checked before anything is opened (check_rig_options). The
// program's refusals end to end: e2e sim_rig_refuses_a_bad_configuration.
#include <cmath>
#include <string>
#include <vector>

#include "firmware/programs/rig_options.hpp"
#include "tests/support/command_line.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using stencil::app::RigOptions;

namespace {

struct Parsed {
  CLI::App app;
  RigOptions options;
  std::string error;
  explicit Parsed(const std::vector<std::string>& words) {
    app::add_rig_options(app, options);
    test::parse_words(app, words);
  }
  bool apply() { return app::apply_rig_config(app, options, error); }
  bool check(board::sherline_suzuki::WorkOffset& offset, control::StockBlock& stock) {
    return app::check_rig_options(options, offset, stock, error);
  }
};

// A job's words with every required option, and `more`.
std::vector<std::string> job_with(std::vector<std::string> more) {
  std::vector<std::string> words{"--tables", "part.stbl", "--serial", "/dev/ttyS0", "--haptic", "can:can0"};
  words.insert(words.end(), more.begin(), more.end());
  return words;
}

}  // namespace

TEST_GROUP(RigOptions){};

TEST(RigOptions, AJobWithoutAFileNeedsTablesSerialAndHaptic) {
  Parsed none({});
  CHECK_FALSE(none.apply());
  STRCMP_EQUAL("--tables: the part's .stbl is required", none.error.c_str());
  Parsed tables({"--tables", "p.stbl"});
  CHECK_FALSE(tables.apply());
  STRCMP_CONTAINS("--serial: the CY545's serial port is required", tables.error.c_str());
  Parsed serial({"--tables", "p.stbl", "--serial", "/dev/ttyS0"});
  CHECK_FALSE(serial.apply());
  STRCMP_CONTAINS("--haptic: the haptic link is required", serial.error.c_str());
  Parsed all(job_with({}));
  CHECK_TRUE(all.apply());
}

TEST(RigOptions, TheGcodeExportNeedsTheJournal) {
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  Parsed without(job_with({"--gcode", "cut.ngc", "--no-journal"}));
  CHECK_TRUE(without.apply());
  CHECK_FALSE(without.check(offset, stock));
  STRCMP_CONTAINS("--gcode writes the program from the job's journal", without.error.c_str());
  Parsed with(job_with({"--gcode", "cut.ngc"}));
  CHECK_TRUE(with.apply());
  CHECK_TRUE_TEXT(with.check(offset, stock), with.error.c_str());
  STRCMP_EQUAL("cut.ngc", with.options.gcode_path.c_str());
}

TEST(RigOptions, CommissioningNeedsOnlyTheSerialPort) {
  Parsed c({"--commission", "--serial", "/dev/ttyS0"});
  CHECK_TRUE(c.apply());
}

TEST(RigOptions, WithoutAFileTheMachineThreadRunsTenBelowTheCycleAndAboveNothing) {
  Parsed c(job_with({"--priority", "60"}));
  CHECK_TRUE(c.apply());
  CHECK_EQUAL(50, c.options.machine_priority);
  Parsed low(job_with({"--priority", "5"}));
  CHECK_TRUE(low.apply());
  CHECK_EQUAL(1, low.options.machine_priority);
}

TEST(RigOptions, TheFileGivesWhatTheCommandLineDoesNot) {
  Parsed c({"--config", STENCIL_RIG_TOML, "--tables", "p.stbl", "--serial", "/dev/ttyUSB1", "--priority", "40"});
  CHECK_TRUE(c.apply());
  STRCMP_EQUAL("/dev/ttyUSB1", c.options.serial_path.c_str());  // the command line's
  STRCMP_EQUAL("pio:/dev/uio0", c.options.haptic.c_str());       // the file's haptic.link
  CHECK_EQUAL(40, c.options.priority);
  CHECK_EQUAL(39, c.options.machine_priority);  // the file's 70, held below the cycle
  CHECK_EQUAL(50U, c.options.jobs.keep_jobs);
  STRCMP_EQUAL("50,25,25", c.options.offset_text.c_str());
}

TEST(RigOptions, ABadFileIsRefusedBeforeAnythingElse) {
  Parsed c(job_with({"--config", "/nonexistent/rig.toml"}));
  CHECK_FALSE(c.apply());
  STRCMP_CONTAINS("/nonexistent/rig.toml", c.error.c_str());
}

TEST(RigOptions, TheDefaultsAreTheRigsHomeAndTheWholeWorkspace) {
  Parsed c(job_with({}));
  CHECK_TRUE(c.apply());
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  CHECK_TRUE(c.check(offset, stock));
  DOUBLES_EQUAL(50.0, offset.home_world_mm.x(), 0.0);
  DOUBLES_EQUAL(25.0, offset.home_world_mm.z(), 0.0);
  DOUBLES_EQUAL(0.0, stock.low_mm.x(), 0.0);
  DOUBLES_EQUAL(50.0, stock.high_mm.x(), 0.0);
  DOUBLES_EQUAL(25.0, stock.high_mm.z(), 0.0);
}

TEST(RigOptions, TheWorkOffsetAndStickOutsAreRead) {
  Parsed c(job_with({"--work-offset", "40,20.5,22", "--tool-stick-out", "12", "--reference-stick-out", "10"}));
  CHECK_TRUE(c.apply());
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  CHECK_TRUE(c.check(offset, stock));
  DOUBLES_EQUAL(20.5, offset.home_world_mm.y(), 0.0);
  DOUBLES_EQUAL(12.0, offset.tool_stick_out_mm, 0.0);
  DOUBLES_EQUAL(10.0, offset.reference_stick_out_mm, 0.0);
}

TEST(RigOptions, AWorkOffsetThatIsNotThreeNumbersIsRefused) {
  for (const char* bad : {"1,2", "1,2,3,4", "1,,3", "1,2,x", "1,2,inf", ""}) {
    Parsed c(job_with({"--work-offset", bad}));
    CHECK_TRUE(c.apply());
    board::sherline_suzuki::WorkOffset offset;
    control::StockBlock stock{};
    CHECK_FALSE(c.check(offset, stock));
    STRCMP_EQUAL((std::string("--work-offset ") + bad + ": expected X,Y,Z in mm").c_str(), c.error.c_str());
  }
}

TEST(RigOptions, TheStockMustLieInsideTheTravelFromTheWorkOffset) {
  Parsed inside(job_with({"--stock", "10,5,0,40,20,8"}));
  CHECK_TRUE(inside.apply());
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  CHECK_TRUE(inside.check(offset, stock));
  DOUBLES_EQUAL(10.0, stock.low_mm.x(), 0.0);
  DOUBLES_EQUAL(8.0, stock.high_mm.z(), 0.0);
  for (const char* bad : {"10,5,0,60,20,8", "40,5,0,10,20,8", "10,5,0,40,20", "10,5,-1,40,20,8"}) {
    Parsed c(job_with({"--stock", bad}));
    CHECK_TRUE(c.apply());
    CHECK_FALSE(c.check(offset, stock));
    STRCMP_CONTAINS("expected X0,Y0,Z0,X1,Y1,Z1 in mm with each high above its low, inside the workspace [0,50]x[0,25]x[0,25]",
                    c.error.c_str());
  }
}

TEST(RigOptions, AnUnknownHapticLinkIsRefused) {
  Parsed c({"--tables", "p.stbl", "--serial", "/dev/ttyS0", "--haptic", "usb:0"});
  CHECK_TRUE(c.apply());
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  CHECK_FALSE(c.check(offset, stock));
  STRCMP_EQUAL("--haptic usb:0: expected pio:/dev/uioN or can:IFACE", c.error.c_str());
}

TEST(RigOptions, ANonFiniteStickOutIsRefused) {
  Parsed c(job_with({}));
  CHECK_TRUE(c.apply());
  c.options.stick_out = std::nan("");  // CLI11's range check lets it through
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  CHECK_FALSE(c.check(offset, stock));
  STRCMP_CONTAINS("--tool-stick-out and --reference-stick-out", c.error.c_str());
}

TEST(RigOptions, AResumeCarriesOnInItsOwnJournalAndFolder) {
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  Parsed journal(job_with({"--resume", "j", "--journal", "k"}));
  CHECK_TRUE(journal.apply());
  CHECK_FALSE(journal.check(offset, stock));
  STRCMP_CONTAINS("--resume carries on in the journal it resumes", journal.error.c_str());
  Parsed out_dir(job_with({"--resume", "j", "--out-dir", "/tmp/jobs"}));
  CHECK_TRUE(out_dir.apply());
  CHECK_FALSE(out_dir.check(offset, stock));
  STRCMP_EQUAL("--out-dir: a --resume writes in its journal's folder", out_dir.error.c_str());
  Parsed alone(job_with({"--resume", "j"}));
  CHECK_TRUE(alone.apply());
  CHECK_TRUE(alone.check(offset, stock));
}

TEST(RigOptions, AReportThatCannotBeWrittenIsRefused) {
  Parsed c(job_with({"--report", "/nonexistent-folder/report.json"}));
  CHECK_TRUE(c.apply());
  board::sherline_suzuki::WorkOffset offset;
  control::StockBlock stock{};
  CHECK_FALSE(c.check(offset, stock));
  STRCMP_EQUAL("/nonexistent-folder/report.json: cannot be written", c.error.c_str());
}
