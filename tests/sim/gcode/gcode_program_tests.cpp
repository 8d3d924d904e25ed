// The G-code reader's pure parts against hand-written text: block numbering (old N words, comments,
// '%' lines, blank lines, CRLF), and rs274's canonical output read into moves (units, arcs in the
// three planes with their sag, full turns and helices), each refusal and malformed line naming its
// source line. The same reader behind the real rs274 is in gcode_program_rs274_tests.cpp.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "sim/gcode/gcode_program.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using Eigen::Vector3d;

namespace {

// rs274's batch output, written as it prints it: "%5d " output number, "N%-6d" (or "N..... "), the call.
class Canon {
 public:
  Canon& call(int line, const std::string& text) {
    char prefix[64];
    if (line > 0) {
      std::snprintf(prefix, sizeof prefix, "%5d N%-6d", ++count_, line);
    } else {
      std::snprintf(prefix, sizeof prefix, "%5d N..... ", ++count_);
    }
    text_ += prefix + text + "\n";
    return *this;
  }
  // A run of block `line`: its marker comment, as number_blocks makes rs274 print it.
  Canon& block(int line) { return call(line, std::string("COMMENT(\"") + kGcodeBlockMarker + "\")"); }
  // What rs274 prints before any block.
  Canon& preamble() {
    return call(0, "USE_LENGTH_UNITS(CANON_UNITS_MM)")
        .call(0, "SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
        .call(0, "SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
        .call(0, "SET_XY_ROTATION(0.0000)")
        .call(0, "SET_FEED_REFERENCE(CANON_XYZ)")
        .call(0, "ON_RESET()");
  }
  [[nodiscard]] const std::string& text() const { return text_; }

 private:
  int count_ = 0;
  std::string text_;
};

GcodeReadOptions options_with(double tolerance_mm) {
  GcodeReadOptions options;
  options.arc_tolerance_mm = tolerance_mm;
  return options;
}

// The error, or "" when it was taken.
std::string parse(const std::string& text, GcodeProgram& program, const GcodeReadOptions& options = {}) {
  std::string error;
  if (parse_canonical(text, options, program, error)) return "";
  CHECK_FALSE(error.empty());
  return error;
}

std::string parse_error(const std::string& text) {
  GcodeProgram program;
  return parse(text, program);
}

void check_vector(const Vector3d& expected, const Vector3d& got, double tolerance = 1e-9) {
  DOUBLES_EQUAL(expected.x(), got.x(), tolerance);
  DOUBLES_EQUAL(expected.y(), got.y(), tolerance);
  DOUBLES_EQUAL(expected.z(), got.z(), tolerance);
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

// Every sampled point of an arc lies on the circle (centre, radius in the plane of axes i, j), and
// every chord's midpoint is within `tolerance` of it: the sag of each chord is at most the tolerance.
void check_on_circle(const std::vector<GcodeMove>& moves, const Vector3d& start, int i, int j, double centre_i,
                     double centre_j, double radius, double tolerance) {
  Vector3d previous = start;
  for (const GcodeMove& move : moves) {
    const double r = std::hypot(move.to_mm[i] - centre_i, move.to_mm[j] - centre_j);
    DOUBLES_EQUAL(radius, r, 1e-9);
    const Vector3d middle = 0.5 * (previous + move.to_mm);
    const double sag = radius - std::hypot(middle[i] - centre_i, middle[j] - centre_j);
    CHECK(sag >= 0.0);
    CHECK(sag <= tolerance + 1e-12);
    previous = move.to_mm;
  }
}

}  // namespace

TEST_GROUP(NumberBlocks){};

TEST(NumberBlocks, NumbersEveryLineAndEndsItWithTheMarker) {
  STRCMP_EQUAL("N1 G21 G90(@)\nN2 G0 X1 Y2(@)\n", number_blocks("G21 G90\nG0 X1 Y2\n").c_str());
}

TEST(NumberBlocks, ReplacesTheProgramsOwnNWordsWhateverTheirSpelling) {
  STRCMP_EQUAL("N1 G0 X1(@)\nN2 G1 X2(@)\nN3 G1 X3(@)\nN4 G1 X4(@)\n",
               number_blocks("N10 G0 X1\nn 2 0G1 X2\nN13.5 G1 X3\n   N7 G1 X4\n").c_str());
}

TEST(NumberBlocks, KeepsTheBlockDeleteSlashBeforeTheNWord) {
  STRCMP_EQUAL("/N1 G1 X2(@)\n/N2 G1 X3(@)\n", number_blocks("/N7 G1 X2\n / G1 X3\n").c_str());
}

TEST(NumberBlocks, PutsTheMarkerLastBeforeASemicolonCommentAndNotInsideParentheses) {
  STRCMP_EQUAL("N1 G1 X1 (a;b) (@); tail (x)\n", number_blocks("G1 X1 (a;b) ; tail (x)\n").c_str());
  STRCMP_EQUAL("N1 (MSG, hello)(@)\n", number_blocks("(MSG, hello)\n").c_str());
  STRCMP_EQUAL("N1 o100 call(@)\n", number_blocks("o100 call\n").c_str());
}

TEST(NumberBlocks, KeepsPercentLinesAsTheyAreAndNumbersBlankLines) {
  STRCMP_EQUAL("%\nN2 (@)\nN3 G0 X1(@)\n  %\n", number_blocks("%\n\nG0 X1\n  %\n").c_str());
}

TEST(NumberBlocks, DropsTheCarriageReturnsOfCrlfLines) {
  STRCMP_EQUAL("N1 G0 X1(@)\nN2 M2(@)\n", number_blocks("G0 X1\r\nM2\r\n").c_str());
}

TEST(NumberBlocks, NumbersALastLineWithoutItsNewline) {
  STRCMP_EQUAL("N1 G0 X1(@)\nN2 M2(@)\n", number_blocks("G0 X1\nM2").c_str());
  STRCMP_EQUAL("", number_blocks("").c_str());
}

TEST_GROUP(ParseCanonical){};

TEST(ParseCanonical, ReadsTraversesAndFeedsWithTheirSourceLines) {
  Canon canon;
  canon.preamble()
      .block(1)
      .call(1, "SET_FEED_RATE(600.0000)")
      .block(2)
      .call(2, "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)")
      .block(3)
      .call(3, "STRAIGHT_FEED(4.0000, 5.0000, -1.0000, 0.0000, 0.0000, 0.0000)")
      .block(4)
      .call(4, "PROGRAM_END()")
      .call(0, "ON_RESET()");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program).c_str());
  LONGS_EQUAL(2, program.moves.size());
  LONGS_EQUAL(2, program.moves[0].line);
  CHECK(program.moves[0].kind == GcodeMoveKind::Traverse);
  check_vector({1, 2, 3}, program.moves[0].to_mm);
  DOUBLES_EQUAL(0.0, program.moves[0].feed_mm_per_min, 0.0);
  LONGS_EQUAL(3, program.moves[1].line);
  CHECK(program.moves[1].kind == GcodeMoveKind::Feed);
  check_vector({4, 5, -1}, program.moves[1].to_mm);
  DOUBLES_EQUAL(600.0, program.moves[1].feed_mm_per_min, 0.0);
  STRCMP_EQUAL("", program.tool.c_str());
}

TEST(ParseCanonical, ConvertsInchCoordinatesAndFeedsToMillimetres) {
  Canon canon;
  canon.preamble()
      .call(1, "SET_FEED_RATE(100.0000)")  // set in mm: stays 100 mm/min after G20
      .call(2, "USE_LENGTH_UNITS(CANON_UNITS_INCHES)")
      .call(3, "STRAIGHT_FEED(1.0000, 0.1969, -0.0787, 0.0000, 0.0000, 0.0000)")
      .call(4, "SET_FEED_RATE(10.0000)")
      .call(5, "STRAIGHT_TRAVERSE(2.0000, 0.0000, 1.0000, 0.0000, 0.0000, 0.0000)")
      .call(6, "STRAIGHT_FEED(2.0000, 1.0000, 1.0000, 0.0000, 0.0000, 0.0000)")
      .call(7, "USE_LENGTH_UNITS(CANON_UNITS_MM)")
      .call(8, "STRAIGHT_FEED(3.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program).c_str());
  LONGS_EQUAL(4, program.moves.size());
  check_vector({25.4, 0.1969 * 25.4, -0.0787 * 25.4}, program.moves[0].to_mm);
  DOUBLES_EQUAL(100.0, program.moves[0].feed_mm_per_min, 1e-12);
  check_vector({50.8, 0.0, 25.4}, program.moves[1].to_mm);
  check_vector({50.8, 25.4, 25.4}, program.moves[2].to_mm);
  DOUBLES_EQUAL(254.0, program.moves[2].feed_mm_per_min, 1e-12);
  check_vector({3, 0, 0}, program.moves[3].to_mm);
  DOUBLES_EQUAL(254.0, program.moves[3].feed_mm_per_min, 1e-12);
}

TEST(ParseCanonical, ReadsLineNumbersTooWideForTheirColumn) {
  // "N%-6d": from N100000 on, the name follows the number without a space.
  const std::string text =
      "    7 N100000SET_FEED_RATE(10.0000)\n"
      "    8 N1234567STRAIGHT_FEED(2.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n";
  GcodeProgram program;
  STRCMP_EQUAL("", parse(text, program).c_str());
  LONGS_EQUAL(1, program.moves.size());
  LONGS_EQUAL(1234567, program.moves[0].line);
}

TEST(ParseCanonical, SamplesAClockwiseXyArcOnItsCircleWithinTheTolerance) {
  // G2 X6 Y5 I1 J0 from X4 Y5 Z-1: a half circle round (5, 5) over the top (clockwise seen from +Z).
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "STRAIGHT_FEED(4.0000, 5.0000, -1.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "ARC_FEED(6.0000, 5.0000, 5.0000, 5.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)");
  const double tolerance = 0.001;
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program, options_with(tolerance)).c_str());
  const std::vector<GcodeMove> arc(program.moves.begin() + 1, program.moves.end());
  // A half turn of radius 1 at 1 um sag: pi / (2 acos(0.999)) = 35.1 -> 36 chords.
  LONGS_EQUAL(36, arc.size());
  check_on_circle(arc, {4, 5, -1}, 0, 1, 5.0, 5.0, 1.0, tolerance);
  for (const GcodeMove& move : arc) {
    LONGS_EQUAL(3, move.line);
    CHECK(move.kind == GcodeMoveKind::Feed);
    DOUBLES_EQUAL(100.0, move.feed_mm_per_min, 0.0);
    CHECK(move.to_mm.y() >= 5.0 - 1e-12);  // over the top, not under
    DOUBLES_EQUAL(-1.0, move.to_mm.z(), 0.0);
  }
  check_vector({5, 6, -1}, arc[17].to_mm);  // halfway: the top
  check_vector({6, 5, -1}, arc.back().to_mm, 0.0);
}

TEST(ParseCanonical, SamplesXzArcsInZThenXOrder) {
  // G18 G2 X5 Z3 I2 K-1 Y7 from X1 Y2 Z3: rs274 prints (Z end, X end, Z centre, X centre, -1, Y end).
  // Clockwise seen from +Y goes from the start over the side of smaller Z: through X3 Z2-sqrt(5).
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "SELECT_PLANE(CANON_PLANE_XZ)")
      .call(3, "ARC_FEED(3.0000, 5.0000, 2.0000, 3.0000, -1, 7.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program, options_with(0.0005)).c_str());
  const std::vector<GcodeMove> arc(program.moves.begin() + 1, program.moves.end());
  check_on_circle(arc, {1, 2, 3}, 2, 0, 2.0, 3.0, std::sqrt(5.0), 0.0005);
  double lowest_z = 10.0;
  for (const GcodeMove& move : arc) lowest_z = std::min(lowest_z, move.to_mm.z());
  DOUBLES_EQUAL(2.0 - std::sqrt(5.0), lowest_z, 0.0005);  // a point within the sag of the lowest
  check_vector({5, 7, 3}, arc.back().to_mm, 0.0);
  // The helix's axis (Y) goes linearly with the angle: halfway round, halfway along.
  const GcodeMove& middle = arc[arc.size() / 2];
  const double angle_swept = std::numbers::pi + 2.0 * std::atan(0.5);  // 233.1 degrees in all
  const double start_angle = std::atan2(-2.0, 1.0);                    // in (Z, X) about the centre
  const double at = std::atan2(middle.to_mm.x() - 3.0, middle.to_mm.z() - 2.0);
  double swept = start_angle - at;  // clockwise: the angle falls
  if (swept < 0.0) swept += 2.0 * std::numbers::pi;
  DOUBLES_EQUAL(2.0 + 5.0 * swept / angle_swept, middle.to_mm.y(), 1e-9);
}

TEST(ParseCanonical, SamplesYzArcsInYThenZOrder) {
  // G19 G3 Y9 Z3 J1 K2 X9 from X5 Y7 Z3: (Y end, Z end, Y centre, Z centre, +1, X end). Counter-
  // clockwise from Y to Z is the short way here, 53 degrees under the centre (8, 5), through Y8 Z5-sqrt(5).
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "STRAIGHT_TRAVERSE(5.0000, 7.0000, 3.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "SELECT_PLANE(CANON_PLANE_YZ)")
      .call(3, "ARC_FEED(9.0000, 3.0000, 8.0000, 5.0000, 1, 9.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program).c_str());
  const std::vector<GcodeMove> arc(program.moves.begin() + 1, program.moves.end());
  check_on_circle(arc, {5, 7, 3}, 1, 2, 8.0, 5.0, std::sqrt(5.0), 0.001);
  double lowest_z = 10.0;
  for (const GcodeMove& move : arc) lowest_z = std::min(lowest_z, move.to_mm.z());
  DOUBLES_EQUAL(5.0 - std::sqrt(5.0), lowest_z, 0.001);
  for (const GcodeMove& move : arc) CHECK(move.to_mm.y() >= 7.0 && move.to_mm.y() <= 9.0);
  check_vector({9, 9, 3}, arc.back().to_mm, 0.0);
}

TEST(ParseCanonical, FollowsFullTurnsAndAHelixEndPoint) {
  // G2 X10 Y0 Z-2 I5 P2 from the origin: half a turn plus one full, Z falling linearly to -2.
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "ARC_FEED(10.0000, 0.0000, 5.0000, 0.0000, -2, -2.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program, options_with(0.01)).c_str());
  check_on_circle(program.moves, {0, 0, 0}, 0, 1, 5.0, 0.0, 5.0, 0.01);
  // Sum the angle swept: 1.5 turns clockwise.
  double swept = 0.0;
  double previous = std::atan2(0.0, -5.0);
  Vector3d last(0, 0, 0);
  for (const GcodeMove& move : program.moves) {
    const double angle = std::atan2(move.to_mm.y(), move.to_mm.x() - 5.0);
    double step = angle - previous;
    if (step > std::numbers::pi) step -= 2.0 * std::numbers::pi;
    if (step < -std::numbers::pi) step += 2.0 * std::numbers::pi;
    CHECK(step < 0.0);
    swept += step;
    previous = angle;
    CHECK(move.to_mm.z() < last.z());
    last = move.to_mm;
  }
  DOUBLES_EQUAL(-3.0 * std::numbers::pi, swept, 1e-9);
  check_vector({10, 0, -2}, program.moves.back().to_mm, 0.0);
}

TEST(ParseCanonical, TakesAnEndOnTheStartAsAFullCircle) {
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "ARC_FEED(1.0000, 0.0000, 0.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program, options_with(0.001)).c_str());
  // A full turn of radius 1 at 1 um: 2 pi / (2 acos(0.999)) = 70.2 -> 71 chords.
  LONGS_EQUAL(1 + 71, program.moves.size());
}

TEST(ParseCanonical, RecordsTheToolLoadedBeforeTheFirstMove) {
  Canon canon;
  canon.call(1, "SELECT_TOOL(3)")
      .call(1, "START_CHANGE()")
      .call(1, "CHANGE_TOOL(3)")
      .call(2, "STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "SELECT_TOOL(4)");  // preparing the next tool changes nothing yet
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program).c_str());
  STRCMP_EQUAL("T3", program.tool.c_str());
}

TEST(ParseCanonical, RefusesAToolNumberThatIsNotAWholeNumber) {
  for (const char* number : {"1.5", "-1", "1e300"}) {
    Canon canon;
    canon.call(4, std::string("SELECT_TOOL(") + number + ")");
    const std::string error = parse_error(canon.text());
    CHECK_TEXT(starts_with(error, "line 4: a tool number that is not a whole number"), error.c_str());
  }
}

TEST(ParseCanonical, RefusesAToolChangeAfterTheFirstMoveNamingItsLine) {
  Canon canon;
  canon.call(2, "STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)")
      .call(17, "SELECT_TOOL(4)")
      .call(17, "START_CHANGE()")
      .call(17, "CHANGE_TOOL(4)");
  const std::string error = parse_error(canon.text());
  CHECK_TEXT(starts_with(error, "line 17: a tool change after the first move"), error.c_str());
}

TEST(ParseCanonical, RefusesCutterRadiusCompensationNamingItsLine) {
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "COMMENT(\"interpreter: cutter radius compensation on left\")")
      .call(4, "STRAIGHT_FEED(10.0000, 2.5527, 5.0000, 0.0000, 0.0000, 0.0000)");
  const std::string error = parse_error(canon.text());
  CHECK_TEXT(starts_with(error, "line 3: cutter radius compensation"), error.c_str());
}

TEST(ParseCanonical, RefusesABlockThatMakesSeveralMovesNamingItsLine) {
  // G81 X5 Y5 Z-2 R1 under G61: four moves of line 6, nothing else to tell it by.
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .block(2)
      .call(2, "STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)")
      .block(6)
      .call(6, "STRAIGHT_TRAVERSE(5.0000, 5.0000, 5.0000, 0.0000, 0.0000, 0.0000)")
      .call(6, "STRAIGHT_TRAVERSE(5.0000, 5.0000, 1.0000, 0.0000, 0.0000, 0.0000)")
      .call(6, "STRAIGHT_FEED(5.0000, 5.0000, -2.0000, 0.0000, 0.0000, 0.0000)");
  const std::string error = parse_error(canon.text());
  CHECK_TEXT(starts_with(error, "line 6: one block making several moves (a canned cycle"), error.c_str());
}

TEST(ParseCanonical, FollowsALoopBodyRunSeveralTimes) {
  // o1 repeat [2] around "G91 G1 X1" on line 9: each run prints its marker before its move.
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .block(9)
      .call(9, "STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
      .block(9)
      .call(9, "STRAIGHT_FEED(2.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program).c_str());
  LONGS_EQUAL(2, program.moves.size());
  check_vector({2, 0, 0}, program.moves[1].to_mm);
}

TEST(ParseCanonical, RefusesWhatMovesTheWorkOrTheToolTipNamingTheLine) {
  struct Case {
    const char* call;
    const char* expected;
  };
  const Case cases[] = {
      {"SET_G5X_OFFSET(1, 10.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)", "line 5: a non-zero work offset"},
      {"SET_G92_OFFSET(1.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)", "line 5: a non-zero G92/G52 offset"},
      {"SET_XY_ROTATION(30.0000)", "line 5: an XY rotation"},
      {"USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 12.9794, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)",
       "line 5: a non-zero tool length offset"},
      {"STRAIGHT_FEED(5.0000, 3.0000, 5.0000, 10.0000, 0.0000, 0.0000)", "line 5: motion in A/B/C"},
      {"STRAIGHT_PROBE(1.0000, 6.0000, -10.0000, 0.0000, 0.0000, 0.0000)", "line 5: probing (G38.x)"},
      {"START_SPEED_FEED_SYNC(1.000000,0)", "line 5: spindle-synchronised motion"},
      {"RIGID_TAP(1.0000, 6.0000, -1.0000)", "line 5: rigid tapping"},
      {"COMMENT(\"interpreter: feed mode set to inverse time\")", "line 5: inverse-time feed (G93)"},
      {"SET_FEED_MODE(0, 1)", "line 5: feed per revolution (G95)"},
      {"NURBS_FEED(3, ...)", "line 5: an unknown canonical call NURBS_FEED"},
      {"USE_LENGTH_UNITS(CANON_UNITS_CM)", "line 5: unknown length units"},
      {"SELECT_PLANE(CANON_PLANE_UV)", "line 5: the plane CANON_PLANE_UV"},
  };
  for (const Case& c : cases) {
    Canon canon;
    canon.call(1, "SET_FEED_RATE(100.0000)")
        .call(2, "STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
        .call(5, c.call);
    const std::string error = parse_error(canon.text());
    CHECK_TEXT(starts_with(error, c.expected), (std::string(c.call) + " gave: " + error).c_str());
  }
}

TEST(ParseCanonical, AcceptsZeroOffsetsAndHarmlessCalls) {
  Canon canon;
  canon.preamble()
      .call(1, "SET_G5X_OFFSET(2, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
      .call(1, "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)")
      .call(1, "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.010000)")
      .call(1, "SET_SPINDLE_SPEED(0, 1000.0000)")
      .call(1, "START_SPINDLE_CLOCKWISE(0)")
      .call(1, "FLOOD_ON()")
      .call(1, "SET_FEED_MODE(0, 0)")
      .call(1, "SET_FEED_RATE(100.0000)")
      .call(1, "COMMENT(\"interpreter: feed mode set to units per minute\")")
      .call(1, "DWELL(0.5000)")
      .call(2, "STRAIGHT_FEED(-0.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "SET_SPINDLE_MODE(0 0.0000)")
      .call(3, "PROGRAM_END()");
  GcodeProgram program;
  STRCMP_EQUAL("", parse(canon.text(), program).c_str());
  LONGS_EQUAL(1, program.moves.size());
}

TEST(ParseCanonical, RefusesAFeedMoveBeforeAnyFeedRate) {
  Canon canon;
  canon.call(2, "STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
  const std::string error = parse_error(canon.text());
  CHECK_TEXT(starts_with(error, "line 3: a feed move with no feed rate"), error.c_str());
  Canon arc;
  arc.call(4, "ARC_FEED(1.0000, 0.0000, 0.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)");
  CHECK(starts_with(parse_error(arc.text()), "line 4: a feed move with no feed rate"));
}

TEST(ParseCanonical, RefusesAProgramWithNoMove) {
  Canon canon;
  canon.preamble().call(1, "SET_FEED_RATE(100.0000)").call(2, "PROGRAM_END()");
  STRCMP_EQUAL("the program makes no move", parse_error(canon.text()).c_str());
  STRCMP_EQUAL("the program makes no move", parse_error("").c_str());
}

TEST(ParseCanonical, RefusesNumbersThatAreNotFiniteNamingTheLine) {
  for (const char* number : {"nan", "-nan", "inf", "-inf", "1e999"}) {
    Canon canon;
    canon.call(1, "SET_FEED_RATE(100.0000)")
        .call(7, std::string("STRAIGHT_FEED(1.0000, ") + number + ", 0.0000, 0.0000, 0.0000, 0.0000)");
    const std::string error = parse_error(canon.text());
    CHECK_TEXT(starts_with(error, "line 7: STRAIGHT_FEED has a number that is not finite"), error.c_str());
  }
}

TEST(ParseCanonical, NamesTheLineOfWhatItCannotRead) {
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)").call(8, "STRAIGHT_FEED(1.0000, x, 0.0000, 0.0000, 0.0000, 0.0000)");
  std::string error = parse_error(canon.text());
  CHECK_TEXT(starts_with(error, "line 8: cannot read the numbers of STRAIGHT_FEED"), error.c_str());

  Canon short_call;
  short_call.call(1, "SET_FEED_RATE(100.0000)").call(9, "STRAIGHT_FEED(1.0000, 2.0000)");
  error = parse_error(short_call.text());
  CHECK_TEXT(starts_with(error, "line 9: STRAIGHT_FEED has 2 numbers, expected 6 to 9"), error.c_str());

  error = parse_error("    1 N12    SET_FEED_RATE(100.0000\n");
  CHECK_TEXT(starts_with(error, "line 12: cannot read rs274's output"), error.c_str());
  error = parse_error("    1 N1     SET_FEED_RATE(100.0000)\nexecuting garbage\n");
  CHECK_TEXT(starts_with(error, "canonical output line 2: cannot read rs274's output \"executing garbage\""),
             error.c_str());
}

TEST(ParseCanonical, RefusesAMoveFromABlockWithNoLineNumber) {
  const std::string error =
      parse_error("    1 N..... STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)\n");
  CHECK_TEXT(starts_with(error, "canonical output line 1: a move from a block with no line number"), error.c_str());
}

TEST(ParseCanonical, RefusesAnArcOfZeroRadiusOrABadRotation) {
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(3, "ARC_FEED(0.0000, 0.0000, 0.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)");
  CHECK(starts_with(parse_error(canon.text()), "line 3: an arc of zero radius"));
  Canon rotation;
  rotation.call(1, "SET_FEED_RATE(100.0000)")
      .call(3, "ARC_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0, 0.0000, 0.0000, 0.0000, 0.0000)");
  CHECK(starts_with(parse_error(rotation.text()), "line 3: ARC_FEED's rotation must be"));
}

TEST(ParseCanonical, RefusesAnArcThatWouldTakeMillionsOfChords) {
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)")
      .call(2, "STRAIGHT_FEED(1000.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)")
      .call(3, "ARC_FEED(1000.0000, 0.0000, 0.0000, 0.0000, 1000, 0.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  const std::string error = parse(canon.text(), program, options_with(1e-6));
  CHECK_TEXT(starts_with(error, "line 3: the arc needs"), error.c_str());
}

TEST(ParseCanonical, RefusesATolerranceThatIsNotAPositiveLength) {
  Canon canon;
  canon.call(1, "SET_FEED_RATE(100.0000)").call(2, "STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
  GcodeProgram program;
  CHECK(starts_with(parse(canon.text(), program, options_with(0.0)), "the arc tolerance must be a positive"));
  CHECK(starts_with(parse(canon.text(), program, options_with(std::nan(""))), "the arc tolerance must be"));
}
