// The G-code reader behind the real rs274 (run through run_rs274_tests.sh, which skips without it):
// a program with G0/G1/G2/G3/G20 read into the expected millimetre points on the right lines, and
// G41, G81 (also under G61), a syntax error and a missing program end refused naming their lines;
// a one-line loop body followed; a missing interpreter and one that never ends reported.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/gcode/gcode_program.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using Eigen::Vector3d;

namespace {

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }
bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

void check_vector(const Vector3d& expected, const Vector3d& got, double tolerance) {
  DOUBLES_EQUAL(expected.x(), got.x(), tolerance);
  DOUBLES_EQUAL(expected.y(), got.y(), tolerance);
  DOUBLES_EQUAL(expected.z(), got.z(), tolerance);
}

}  // namespace

TEST_GROUP(ReadGcodeProgram) {
  std::string folder;
  std::string path;

  void setup() override {
    // A folder and a file name with spaces: rs274 is spawned with no shell in between.
    std::string name = (std::filesystem::temp_directory_path() / "stencil gcode XXXXXX").string();
    CHECK(mkdtemp(name.data()) != nullptr);
    folder = name;
    path = folder + "/cam program.ngc";
  }
  void teardown() override {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
  }

  void write(const std::string& text) const {
    std::ofstream out(path, std::ios::binary);
    out << text;
  }

  std::string read_error(const std::string& text, const GcodeReadOptions& options = {}) const {
    write(text);
    GcodeProgram program;
    std::string error;
    CHECK_FALSE(read_gcode_program(path, options, program, error));
    return error;
  }
};

TEST(ReadGcodeProgram, ReadsG0G1G2G3AndInchesIntoMillimetrePointsOnTheirLines) {
  write(
      "%\r\n"                         // 1 (CRLF, as Windows CAM writes it)
      "(a CAM-like program)\r\n"      // 2
      "N100 G21 G90 G17 G94\r\n"      // 3: its own N word is replaced
      "T1 M6 ; the tool\r\n"          // 4
      "F600\r\n"                      // 5
      "G0 X1 Y2 Z3\r\n"               // 6
      "\r\n"                          // 7
      "G1 X4 Y5 Z-1 (down)\r\n"       // 8
      "G2 X6 Y5 I1 J0\r\n"            // 9: half a turn clockwise over the top
      "G3 X4 Y5 I-1 J0 Z-2\r\n"       // 10: back over the top, down 1 mm
      "G20\r\n"                       // 11
      "G1 X1 F10\r\n"                 // 12: one inch, 10 in/min
      "M2\r\n"                        // 13
      "%\r\n");                       // 14
  GcodeReadOptions options;
  options.arc_tolerance_mm = 0.001;
  GcodeProgram program;
  std::string error;
  CHECK_TEXT(read_gcode_program(path, options, program, error), error.c_str());
  STRCMP_EQUAL("T1", program.tool.c_str());
  CHECK(program.moves.size() > 4);

  const GcodeMove& traverse = program.moves[0];
  LONGS_EQUAL(6, traverse.line);
  CHECK(traverse.kind == GcodeMoveKind::Traverse);
  check_vector({1, 2, 3}, traverse.to_mm, 0.0);
  const GcodeMove& feed = program.moves[1];
  LONGS_EQUAL(8, feed.line);
  CHECK(feed.kind == GcodeMoveKind::Feed);
  check_vector({4, 5, -1}, feed.to_mm, 0.0);
  DOUBLES_EQUAL(600.0, feed.feed_mm_per_min, 0.0);

  std::size_t i = 2;
  int line_9 = 0;
  for (; i < program.moves.size() && program.moves[i].line == 9; ++i, ++line_9) {
    const Vector3d& p = program.moves[i].to_mm;
    DOUBLES_EQUAL(1.0, std::hypot(p.x() - 5.0, p.y() - 5.0), 1e-9);
    CHECK(p.y() >= 5.0 - 1e-9);  // clockwise from X4 to X6 passes over the top
    DOUBLES_EQUAL(-1.0, p.z(), 0.0);
  }
  LONGS_EQUAL(36, line_9);  // a half turn of radius 1 mm at 1 um sag
  check_vector({6, 5, -1}, program.moves[i - 1].to_mm, 0.0);
  double previous_z = -1.0;
  for (; i < program.moves.size() && program.moves[i].line == 10; ++i) {
    const Vector3d& p = program.moves[i].to_mm;
    DOUBLES_EQUAL(1.0, std::hypot(p.x() - 5.0, p.y() - 5.0), 1e-9);
    CHECK(p.y() >= 5.0 - 1e-9);  // counter-clockwise from X6 back to X4 passes over the top too
    CHECK(p.z() < previous_z);
    previous_z = p.z();
  }
  check_vector({4, 5, -2}, program.moves[i - 1].to_mm, 0.0);

  LONGS_EQUAL(program.moves.size() - 1, i);
  const GcodeMove& inch = program.moves[i];
  LONGS_EQUAL(12, inch.line);
  // rs274 prints inches to 4 decimals: Y5 mm comes back as 0.1969 in (5.00126 mm).
  check_vector({25.4, 5.0, -2.0}, inch.to_mm, 0.0013);
  DOUBLES_EQUAL(254.0, inch.feed_mm_per_min, 1e-9);
}

TEST(ReadGcodeProgram, RefusesCutterRadiusCompensationNamingItsLine) {
  const std::string error = read_error(
      "G21 G90 G17 F100\n"
      "G0 X0 Y0 Z5\n"
      "G41 D1 G1 X10 Y0\n"
      "G1 X20\n"
      "G40 G1 X30\n"
      "M2\n");
  CHECK_TEXT(starts_with(error, path + ": line 3: cutter radius compensation"), error.c_str());
}

TEST(ReadGcodeProgram, RefusesACannedCycleNamingItsLine) {
  const std::string error = read_error(
      "G21 G90 G17 F100\n"
      "G0 X0 Y0 Z5\n"
      "G1 X1\n"
      "G81 X5 Y5 Z-2 R1\n"
      "G80\n"
      "M2\n");
  CHECK_TEXT(starts_with(error, path + ": line 4: one block making several moves (a canned cycle"), error.c_str());
}

TEST(ReadGcodeProgram, RefusesACannedCycleUnderExactPathNamingItsLine) {
  // Under G61 the cycle's own switch to exact path is not printed: only the marker tells it.
  const std::string error = read_error(
      "G21 G90 G17 G61 F100\n"
      "G0 X0 Y0 Z5\n"
      "G83 X5 Y5 Z-2 R1 Q0.5\n"
      "G80\n"
      "M2\n");
  CHECK_TEXT(starts_with(error, path + ": line 3: one block making several moves"), error.c_str());
}

TEST(ReadGcodeProgram, NamesTheLineOfASyntaxError) {
  const std::string error = read_error(
      "G21 F100\n"
      "G1 X1\n"
      "G1 X2 Q\n"
      "M2\n");
  CHECK_TEXT(starts_with(error, path + ": line 3: rs274: "), error.c_str());
  CHECK_TEXT(contains(error, "(in \"G1 X2 Q\")"), error.c_str());
}

TEST(ReadGcodeProgram, NamesTheLastLineOfAProgramWithNoEnd) {
  const std::string error = read_error("G21 F100\nG1 X1\n");
  CHECK_TEXT(starts_with(error, path + ": line 2: rs274: File ended with no percent sign or program end"),
             error.c_str());
}

TEST(ReadGcodeProgram, RefusesAWorkOffsetNamingItsLine) {
  const std::string error = read_error("G21 F100\nG1 X1\nG10 L2 P1 X10\nG1 X2\nM2\n");
  CHECK_TEXT(starts_with(error, path + ": line 3: a non-zero work offset"), error.c_str());
}

TEST(ReadGcodeProgram, FollowsALoopWhoseBodyIsOneLine) {
  write(
      "G21 G90 F100\n"
      "#1 = 0\n"
      "o1 while [#1 LT 3]\n"
      "G1 X[#1 + 1]\n"
      "#1 = [#1 + 1]\n"
      "o1 endwhile\n"
      "o2 repeat [2]\n"
      "G91 G1 Y1\n"
      "o2 endrepeat\n"
      "M2\n");
  GcodeProgram program;
  std::string error;
  CHECK_TEXT(read_gcode_program(path, {}, program, error), error.c_str());
  LONGS_EQUAL(5, program.moves.size());
  for (int k = 0; k < 3; ++k) {
    LONGS_EQUAL(4, program.moves[static_cast<std::size_t>(k)].line);
    DOUBLES_EQUAL(k + 1.0, program.moves[static_cast<std::size_t>(k)].to_mm.x(), 0.0);
  }
  LONGS_EQUAL(8, program.moves[4].line);
  check_vector({3, 2, 0}, program.moves[4].to_mm, 0.0);
}

TEST(ReadGcodeProgram, RefusesAProgramThatMakesNoMove) {
  STRCMP_EQUAL((path + ": the program makes no move").c_str(), read_error("G21 F100\nM2\n").c_str());
}

TEST(ReadGcodeProgram, RefusesAnEmptyFile) {
  // No block to name: rs274's own words, with its exit status.
  STRCMP_EQUAL((path + ": rs274 failed (exit status 1): File ended with no percent sign").c_str(),
               read_error("").c_str());
}

TEST(ReadGcodeProgram, ReportsAMissingInterpreter) {
  GcodeReadOptions options;
  options.rs274 = "/nonexistent/rs274";
  const std::string error = read_error("G0 X1\nM2\n", options);
  CHECK_TEXT(starts_with(error, path + ": cannot run /nonexistent/rs274"), error.c_str());
}

TEST(ReadGcodeProgram, StopsAProgramThatNeverEnds) {
  GcodeReadOptions options;
  options.timeout_s = 1.0;
  options.max_output_bytes = 1 << 20;
  const std::string error = read_error("G21 F100\no1 while [1]\nG1 X1\no1 endwhile\nM2\n", options);
  CHECK_TEXT(contains(error, "(a loop without end?)"), error.c_str());
}

TEST(ReadGcodeProgram, ReportsAFileItCannotRead) {
  GcodeProgram program;
  std::string error;
  CHECK_FALSE(read_gcode_program(folder + "/missing.ngc", {}, program, error));
  CHECK_TEXT(starts_with(error, folder + "/missing.ngc: cannot read"), error.c_str());
}
