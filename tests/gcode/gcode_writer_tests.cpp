// The program's text: the header a CNC needs to move what was checked, feeds from the recorded
// times, only the axes that change, and the way out.
#include <cstdio>
#include <string>
#include <vector>

#include "firmware/services/gcode/gcode_writer.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using gcode::CutMove;
using gcode::MoveKind;

namespace {

std::vector<std::string> program_lines(const std::vector<CutMove>& moves, const Eigen::Vector3d& start,
                                       const gcode::ProgramSettings& settings) {
  std::FILE* file = std::tmpfile();
  CHECK(file != nullptr);
  CHECK(gcode::write_program(file, moves, start, settings));
  std::rewind(file);
  std::vector<std::string> lines;
  char line[256];
  while (std::fgets(line, sizeof line, file) != nullptr) {
    std::string text(line);
    text.pop_back();
    lines.push_back(text);
  }
  std::fclose(file);
  return lines;
}

gcode::ProgramSettings settings() {
  gcode::ProgramSettings s;
  s.comments = {"a test"};
  s.tool = "ball end mill d 3.000 mm";
  s.spindle_rpm = 2800.0;
  s.safe_z_mm = 25.0;
  return s;
}

}  // namespace

TEST_GROUP(GcodeWriter){};

TEST(GcodeWriter, TheHeaderSetsMillimetresAbsoluteWorkCoordinatesAndExactPath) {
  const std::vector<std::string> lines = program_lines({}, {50.0, 25.0, 20.0}, settings());
  const std::vector<std::string> expected{"%", "(a test)", "G21 G90 G94 G17 G40 G49 G54 G61",
                                          "T1 M6 (ball end mill d 3.000 mm)", "S2800 M3", "G0 Z25", "G0 X50 Y25",
                                          "G0 Z20", "G0 Z25", "M5", "M2", "%"};
  LONGS_EQUAL(expected.size(), lines.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    STRCMP_EQUAL(expected[i].c_str(), lines[i].c_str());
  }
}

TEST(GcodeWriter, FeedsAreTheRecordedSpeedWrittenWhenTheyChange) {
  const std::vector<CutMove> moves{{MoveKind::Feed, {49.0, 25.0, 25.0}, 0.5},   // 1 mm in 0.5 s: 120 mm/min
                                   {MoveKind::Feed, {48.0, 25.0, 25.0}, 0.5},   // the same: no F
                                   {MoveKind::Feed, {48.0, 24.0, 25.0}, 1.0},   // 60 mm/min
                                   {MoveKind::Traverse, {48.0, 24.0, 25.0 + 1e-7}, 0.0}};  // below the precision: nothing
  const std::vector<std::string> lines = program_lines(moves, {50.0, 25.0, 25.0}, settings());
  STRCMP_EQUAL("G1 X49 F120", lines[7].c_str());
  STRCMP_EQUAL("G1 X48", lines[8].c_str());
  STRCMP_EQUAL("G1 Y24 F60", lines[9].c_str());
  STRCMP_EQUAL("G0 Z25", lines[10].c_str());
}

TEST(GcodeWriter, CoordinatesKeepFiveDecimalsAndNoNegativeZero) {
  const std::vector<CutMove> moves{{MoveKind::Feed, {-0.000001, 1.0 / 640.0, 25.0}, 1.0}};  // about 1 mm in 1 s
  const std::vector<std::string> lines = program_lines(moves, {1.0, 0.0, 25.0}, settings());
  STRCMP_EQUAL("G1 X0 Y0.00156 F60", lines[7].c_str());
}

TEST(GcodeWriter, AVerySlowMoveIsWrittenAtTheSlowestFeed) {
  gcode::ProgramSettings s = settings();
  s.min_feed_mm_per_min = 1.0;
  const std::vector<CutMove> moves{{MoveKind::Feed, {49.999, 25.0, 25.0}, 10.0}};  // 0.006 mm/min
  const std::vector<std::string> lines = program_lines(moves, {50.0, 25.0, 25.0}, s);
  STRCMP_EQUAL("G1 X49.999 F1", lines[7].c_str());
}

TEST(GcodeWriter, TheWayOutRetractsAboveTheLastPointThenStopsTheSpindle) {
  const std::vector<CutMove> moves{{MoveKind::Feed, {40.0, 20.0, 5.0}, 1.0}};
  const std::vector<std::string> lines = program_lines(moves, {50.0, 25.0, 25.0}, settings());
  const std::size_t n = lines.size();
  STRCMP_EQUAL("G0 Z25", lines[n - 4].c_str());
  STRCMP_EQUAL("M5", lines[n - 3].c_str());
  STRCMP_EQUAL("M2", lines[n - 2].c_str());
}

TEST(GcodeWriter, ParenthesesInACommentDoNotNestIt) {
  gcode::ProgramSettings s = settings();
  s.comments = {"the cut of /jobs/a (copy)/job.journal"};
  s.tool = "ball (3 mm)";
  const std::vector<std::string> lines = program_lines({}, {50.0, 25.0, 25.0}, s);
  STRCMP_EQUAL("(the cut of /jobs/a [copy]/job.journal)", lines[1].c_str());
  STRCMP_EQUAL("T1 M6 (ball [3 mm])", lines[3].c_str());
}

TEST(GcodeWriter, AFailedWriteIsReported) {
  std::FILE* read_only = std::fopen("/dev/null", "r");
  CHECK(read_only != nullptr);
  CHECK_FALSE(gcode::write_program(read_only, {}, {50.0, 25.0, 25.0}, settings()));
  std::fclose(read_only);
}
