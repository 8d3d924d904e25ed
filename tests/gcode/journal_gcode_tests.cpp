// A journal written as a program: on the job's own tables and rig only, never half a file, and the
// program holds the legs the journal's targets make.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/gcode/journal_gcode.hpp"
#include "tests/support/journal_fixtures.hpp"
#include "tests/support/sample_tables.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct Fixture {
  tablegen::TableBytes bytes;
  tables::PartTables part{};
  testing::TempJournal journal;
  std::string out = journal.path + ".ngc";

  Fixture() : bytes(test::make_table(test::default_part(), test::default_job_options(2))) {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  }
  ~Fixture() { std::remove(out.c_str()); }

  // A job: homed, then the targets given (each a staircase X, Y, Z), ended.
  void write(const std::vector<Eigen::Vector3d>& targets, std::uint32_t tables_crc32, const std::string& job = "job") {
    journal::JournalWriter writer;
    journal::JournalStart start = testing::start_of();
    start.tables_crc32 = tables_crc32;
    start.job = job;
    CHECK(writer.open(journal.path, start));
    CHECK(writer.append_homed(0));
    std::uint64_t update = 0;
    for (const Eigen::Vector3d& t : targets) {
      ++update;
      CHECK(writer.append_machine_command({update, static_cast<std::int64_t>(update) * 100'000'000, {}, {0, 1, 2}, {t.x(), t.y(), t.z()}}));
      CHECK(writer.write_machine_commands());
    }
    CHECK(writer.append_end(0, control::SafeReason::None));
    CHECK(writer.close());
  }

  [[nodiscard]] gcode::JournalExport settings() const {
    gcode::JournalExport s;
    s.path = {motion::MachinePath::Staircase, {50.0, 25.0, 25.0}, 0.1};
    s.program.safe_z_mm = 25.0;
    s.source_name = "test.journal";
    return s;
  }

  [[nodiscard]] std::string program() const {
    std::ifstream in(out);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
};

}  // namespace

TEST_GROUP(JournalGcode){};

TEST(JournalGcode, TheTargetsBecomeTheirLegsAfterTheHeader) {
  Fixture f;
  f.write({{49.0, 25.0, 25.0}, {48.0, 24.0, 24.0}}, f.part.header.crc32);
  gcode::ExportSummary summary;
  std::string error;
  CHECK_TEXT(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), f.out, summary, error), error.c_str());
  LONGS_EQUAL(2, summary.targets);
  LONGS_EQUAL(1, summary.homings);
  LONGS_EQUAL(4, summary.legs);   // X; then X, Y, Z
  LONGS_EQUAL(4, summary.moves);  // the X legs are in line but not at one speed (1 mm in 0.1 s, then in 1/3 of it)
  const std::string text = f.program();
  CHECK(text.find("G21 G90 G94 G17 G40 G49 G54 G61\n") != std::string::npos);
  CHECK(text.find("(the legal cut of test.journal, as the mill was commanded)") != std::string::npos);
  CHECK(text.find("T1 M6 (ball end mill d 3.000 mm") != std::string::npos);
  CHECK(text.find("G0 X50 Y25\nG1 X49 F600\nG1 X48 F1800\nG1 Y24\nG1 Z24\nG0 Z25\nM5\nM2\n%\n") != std::string::npos);
}

TEST(JournalGcode, InMachineCoordinatesEveryMoveIsG53FromHomeAlongTheMachinesAxes) {
  Fixture f;
  f.write({{49.0, 25.0, 25.0}, {48.0, 24.0, 24.0}}, f.part.header.crc32);
  gcode::JournalExport settings = f.settings();
  settings.machine_coordinates = true;
  settings.machine_sign = {-1, -1, -1};  // the Sherline's table moves under the tool; Z counts down from home
  gcode::ExportSummary summary;
  std::string error;
  CHECK_TEXT(gcode::export_journal_gcode(f.journal.path, f.part, settings, f.out, summary, error), error.c_str());
  const std::string text = f.program();
  CHECK(text.find("G53 G0 Z0\nG53 G0 X0 Y0\nG53 G1 X1 F600\nG53 G1 X2 F1800\nG53 G1 Y1\nG53 G1 Z1\nG53 G0 Z0\nM5\n") !=
        std::string::npos);
  CHECK(text.find("the machine's own coordinates") != std::string::npos);
}

TEST(JournalGcode, OtherTablesThanTheJobsAreRefused) {
  Fixture f;
  f.write({{49.0, 25.0, 25.0}}, f.part.header.crc32 ^ 1U);
  gcode::ExportSummary summary;
  std::string error;
  CHECK_FALSE(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), f.out, summary, error));
  CHECK(error.find("recorded on other tables") != std::string::npos);
  CHECK(std::fopen(f.out.c_str(), "r") == nullptr);
}

TEST(JournalGcode, AnotherRigsJobIsRefusedNamingTheConfiguration) {
  Fixture f;
  f.write({{49.0, 25.0, 25.0}}, f.part.header.crc32, "tables=x config-crc32=0badf00d mill-truth-crc32=00000000");
  gcode::ExportSummary summary;
  std::string error;
  CHECK_FALSE(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), f.out, summary, error));
  CHECK(error.find("a configuration of CRC-32 0badf00d") != std::string::npos);
  gcode::JournalExport configured = f.settings();
  configured.config_crc32 = 0x0badf00d;
  CHECK_TEXT(gcode::export_journal_gcode(f.journal.path, f.part, configured, f.out, summary, error), error.c_str());
}

TEST(JournalGcode, ARigJobsRecordedTouchOffIsItsHome) {
  Fixture f;
  f.write({{39.0, 20.0, 19.0}}, f.part.header.crc32,
          "work-offset=40.000000,20.000000,20.000000 tool-stick-out=1.500000 reference-stick-out=0.500000 "
          "stock=0,0,0,50,25,25 config=compiled-in");
  gcode::ExportSummary summary;
  std::string error;
  CHECK_TEXT(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), f.out, summary, error), error.c_str());
  // Home: the offset, its tip 1 mm lower for a tool sticking out 1 mm more than the touch-off's.
  CHECK(f.program().find("G0 Z19\nG0 X40 Y20\nG1 X39 F600\nG0 Z19\n") != std::string::npos);
}

TEST(JournalGcode, AJobThatNeverMovedTheMillWritesNoProgram) {
  Fixture f;
  f.write({}, f.part.header.crc32);
  gcode::ExportSummary summary;
  std::string error;
  CHECK_FALSE(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), f.out, summary, error));
  CHECK(error.find("no target") != std::string::npos);
}

TEST(JournalGcode, AnUnwritableProgramLeavesNothingBehind) {
  Fixture f;
  f.write({{49.0, 25.0, 25.0}}, f.part.header.crc32);
  gcode::ExportSummary summary;
  std::string error;
  CHECK_FALSE(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), "/nonexistent/cut.ngc", summary, error));
  CHECK(error.find("/nonexistent/cut.ngc: cannot be written") != std::string::npos);
}

TEST(JournalGcode, NotAJournalIsTheReadersError) {
  Fixture f;
  std::FILE* file = std::fopen(f.journal.path.c_str(), "w");
  std::fputs("G1 X1\n", file);
  std::fclose(file);
  gcode::ExportSummary summary;
  std::string error;
  CHECK_FALSE(gcode::export_journal_gcode(f.journal.path, f.part, f.settings(), f.out, summary, error));
  CHECK(!error.empty());
}
