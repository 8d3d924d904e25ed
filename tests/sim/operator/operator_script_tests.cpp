// The simulated operator against hand-worked scripts: the CSV reader (what it takes, and for bad
// input an error naming the file, the line and the field), the writer's exact round trip, the walk
// between points, the way back into a stopped job, the patterns' ends, and the hand's spring.
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <unistd.h>

#include "sim/operator/operator_script.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using Eigen::Vector3d;

namespace {

// Parses `text` as the file "ops.csv"; the error, or "" when it was taken.
std::string parse(const std::string& text, OperatorScript& script) {
  std::istringstream in(text);
  std::string error;
  if (parse_operator_csv(in, "ops.csv", script, error)) return "";
  CHECK_FALSE(error.empty());
  return error;
}

std::string parse_error(const std::string& text) {
  OperatorScript script;
  return parse(text, script);
}

void check_vector(const Vector3d& expected, const Vector3d& got, double tolerance = 1e-12) {
  DOUBLES_EQUAL(expected.x(), got.x(), tolerance);
  DOUBLES_EQUAL(expected.y(), got.y(), tolerance);
  DOUBLES_EQUAL(expected.z(), got.z(), tolerance);
}

}  // namespace

TEST_GROUP(OperatorScript){};

TEST(OperatorScript, ACsvTakesFourOrSixFieldsAfterAHeaderAndSkipsCommentsAndBlankLines) {
  OperatorScript script;
  STRCMP_EQUAL("", parse("t_s,x_mm,y_mm,z_mm\n# a comment\n0,1,2,3\n\n0.5, 4 ,5,6,0.1,-0.2\r\n", script).c_str());
  LONGS_EQUAL(2, script.t_s.size());
  check_vector({1.0, 2.0, 3.0}, script.device_mm[0]);
  DOUBLES_EQUAL(0.0, script.angles_rad[0].x(), 0.0);  // four fields: no angles
  check_vector({4.0, 5.0, 6.0}, script.device_mm[1]);
  DOUBLES_EQUAL(0.1, script.angles_rad[1].x(), 0.0);
  DOUBLES_EQUAL(-0.2, script.angles_rad[1].y(), 0.0);
  DOUBLES_EQUAL(0.5, script.duration_s(), 0.0);
}

TEST(OperatorScript, ABadFieldIsNamedWithItsFileLineAndPlace) {
  STRCMP_EQUAL("ops.csv: line 3: field 2 'abc' is not a finite number",
               parse_error("t_s,x_mm,y_mm,z_mm\n0,1,2,3\n1,abc,2,3\n").c_str());
  STRCMP_EQUAL("ops.csv: line 1: field 4 '3mm' is not a finite number", parse_error("0,1,2,3mm\n").c_str());
  STRCMP_EQUAL("ops.csv: line 1: field 3 'nan' is not a finite number", parse_error("0,1,nan,3\n").c_str());
  STRCMP_EQUAL("ops.csv: line 1: field 2 '1e999' is not a finite number", parse_error("0,1e999,2,3\n").c_str());
  STRCMP_EQUAL("ops.csv: line 1: field 2 '' is not a finite number", parse_error("0,,2,3\n").c_str());
  // An empty last field is refused as well, not read as a row of four (getline drops it).
  STRCMP_EQUAL("ops.csv: line 2: field 5 '' is not a finite number", parse_error("0,1,2,3\n1,1,2,3,\n").c_str());
}

TEST(OperatorScript, AFileWithWindowsLineEndsReadsAsItsRowsBlankLinesIncluded) {
  OperatorScript script;
  STRCMP_EQUAL("", parse("t_s,x_mm,y_mm,z_mm\r\n0,1,2,3\r\n\r\n1,4,5,6\r\n", script).c_str());
  LONGS_EQUAL(2, script.t_s.size());
  DOUBLES_EQUAL(6.0, script.device_mm[1].z(), 0.0);
  STRCMP_EQUAL("ops.csv: line 2: field 2 'x' is not a finite number", parse_error("0,1,2,3\r\n1,x,2,3\r\n").c_str());
}

TEST(OperatorScript, AWrongFieldCountTimesThatDoNotIncreaseAndNoRowsAreRefused) {
  STRCMP_EQUAL("ops.csv: line 2: 5 fields; expected t_s,x_mm,y_mm,z_mm[,a_rad,b_rad]",
               parse_error("0,1,2,3\n1,1,2,3,4\n").c_str());
  STRCMP_EQUAL("ops.csv: line 2: 3 fields; expected t_s,x_mm,y_mm,z_mm[,a_rad,b_rad]", parse_error("0,1,2,3\n1,2,3\n").c_str());
  STRCMP_EQUAL("ops.csv: line 3: t_s 1.000000 does not increase (the previous row's is 1.000000)",
               parse_error("0,1,2,3\n1,1,2,3\n1,1,2,3\n").c_str());
  STRCMP_EQUAL("ops.csv: no rows; expected t_s,x_mm,y_mm,z_mm[,a_rad,b_rad]", parse_error("t_s,x,y,z\n# nothing\n").c_str());
}

TEST(OperatorScript, AFieldIsAFiniteNumberAllOfItWithTrailingBlanksAndACarriageReturnAside) {
  double value = 0.0;
  CHECK_TRUE(parse_finite_field("-2.5e-3 \r", value));
  DOUBLES_EQUAL(-2.5e-3, value, 0.0);
  CHECK_TRUE(parse_finite_field(" 7", value));
  CHECK_FALSE(parse_finite_field("7 x", value));
  CHECK_FALSE(parse_finite_field("", value));
  CHECK_FALSE(parse_finite_field("inf", value));
  CHECK_FALSE(parse_finite_field("x7", value));
}

TEST(OperatorScript, AWrittenScriptReadsBackBitForBitAndMissingFilesAreNamed) {
  OperatorScript script;
  script.t_s = {0.0, 0.1, 1.0 / 3.0};
  script.device_mm = {{0.1, -0.2, 1e-17}, {1.0 / 7.0, 2.0, 3.0}, {-4.0, 5.5, 6.25}};
  script.angles_rad = {{0.0, 0.0}, {0.3, -0.7}, {1.0 / 9.0, 0.0}};
  char path[] = "/tmp/operator_script_testsXXXXXX";
  const int fd = ::mkstemp(path);
  CHECK_TRUE(fd >= 0);
  ::close(fd);
  std::string error;
  CHECK_TRUE(write_operator_csv(path, script, error));
  OperatorScript back;
  CHECK_TRUE(read_operator_csv(path, back, error));
  std::remove(path);
  LONGS_EQUAL(3, back.t_s.size());
  for (std::size_t i = 0; i < 3; ++i) {
    DOUBLES_EQUAL(script.t_s[i], back.t_s[i], 0.0);
    check_vector(script.device_mm[i], back.device_mm[i], 0.0);
    DOUBLES_EQUAL(script.angles_rad[i].x(), back.angles_rad[i].x(), 0.0);
    DOUBLES_EQUAL(script.angles_rad[i].y(), back.angles_rad[i].y(), 0.0);
  }
  CHECK_FALSE(read_operator_csv(path, back, error));
  STRCMP_EQUAL((std::string(path) + ": cannot be read").c_str(), error.c_str());
}

TEST(OperatorScript, TheHandIsOnTheStraightLineBetweenRowsAndHeldAtTheEnds) {
  OperatorScript script;
  STRCMP_EQUAL("", parse("0,0,0,0\n2,4,-2,8,0.5,0.25\n", script).c_str());
  check_vector({1.0, -0.5, 2.0}, script.position_at(0.5));
  check_vector({0.0, 0.0, 0.0}, script.position_at(-1.0));
  check_vector({4.0, -2.0, 8.0}, script.position_at(5.0));
  // Angles are the row's from its time on (no blend).
  DOUBLES_EQUAL(0.0, script.angles_at(1.9).x(), 0.0);
  DOUBLES_EQUAL(0.5, script.angles_at(2.0).x(), 0.0);
  check_vector(Vector3d::Zero(), OperatorScript{}.position_at(1.0));
}

TEST(OperatorScript, WalkingTakesTheWorldDistanceOverTheSpeedAndScalesPointsToTheDevice) {
  OperatorScript script;
  walk_to(script, {1.0, 2.0, 3.0}, 5.0, 0.5);
  LONGS_EQUAL(1, script.t_s.size());
  DOUBLES_EQUAL(0.0, script.t_s[0], 0.0);  // the first point is where the hand starts
  check_vector({0.5, 1.0, 1.5}, script.device_mm[0]);
  walk_to(script, {4.0, 6.0, 3.0}, 5.0, 0.5);  // 5 mm of world at 5 mm/s
  DOUBLES_EQUAL(1.0, script.t_s[1], 1e-12);
  check_vector({2.0, 3.0, 1.5}, script.device_mm[1]);
}

TEST(OperatorScript, TheWayBackIntoAStoppedJobGoesAlongXThenYAtHomesHeightThenDownThenOn) {
  OperatorScript script;
  STRCMP_EQUAL("", parse("0,0,0,0\n1,10,0,0\n2,10,10,0\n", script).c_str());
  double approach_s = 0.0;
  const OperatorScript resumed = carry_on(script, 1.5, {0.0, 0.0, 20.0}, {10.0, 5.0, 2.0}, 1.0, 1.0, approach_s);
  LONGS_EQUAL(6, resumed.t_s.size());
  check_vector({0.0, 0.0, 20.0}, resumed.device_mm[0]);
  check_vector({10.0, 0.0, 20.0}, resumed.device_mm[1]);
  check_vector({10.0, 5.0, 20.0}, resumed.device_mm[2]);
  check_vector({10.0, 5.0, 2.0}, resumed.device_mm[3]);
  check_vector({10.0, 5.0, 0.0}, resumed.device_mm[4]);  // where the script was at 1.5 s
  DOUBLES_EQUAL(10.0 + 5.0 + 18.0 + 2.0, approach_s, 1e-12);
  check_vector({10.0, 10.0, 0.0}, resumed.device_mm[5]);  // then the rest, as late as it was
  DOUBLES_EQUAL(approach_s + 0.5, resumed.t_s[5], 1e-12);
}

TEST(OperatorScript, EveryPatternStartsAndEndsAtHomeAndItsTimesIncrease) {
  const StockBox stock{{0.0, 0.0, 0.0}, {6.0, 4.0, 3.0}};
  const Vector3d home(3.0, 2.0, 10.0);
  const auto floor = [](double, double) { return 0.0; };
  for (const Pattern pattern : {Pattern::Raster, Pattern::Plunge, Pattern::Thinwall, Pattern::Random}) {
    const OperatorScript script = make_pattern(pattern, stock, home, 2.0, 0.5, 7, floor, 20);
    CHECK_TRUE(script.t_s.size() > 3);
    check_vector(0.5 * home, script.device_mm.front());
    check_vector(0.5 * home, script.device_mm.back());
    for (std::size_t i = 1; i < script.t_s.size(); ++i) CHECK_TRUE(script.t_s[i] >= script.t_s[i - 1]);
  }
  // The random walk is the seed's: the same seed, the same walk.
  const OperatorScript a = make_pattern(Pattern::Random, stock, home, 2.0, 0.5, 7, floor, 20);
  const OperatorScript b = make_pattern(Pattern::Random, stock, home, 2.0, 0.5, 7, floor, 20);
  const OperatorScript c = make_pattern(Pattern::Random, stock, home, 2.0, 0.5, 8, floor, 20);
  check_vector(a.device_mm[5], b.device_mm[5], 0.0);
  CHECK_TRUE((a.device_mm[5] - c.device_mm[5]).norm() > 1e-9);
}

TEST(OperatorScript, PlungesGoToAMillimetreBelowTheFloorEveryTwoMillimetres) {
  const StockBox stock{{0.0, 0.0, 0.0}, {4.0, 2.0, 3.0}};
  const OperatorScript script = make_pattern(Pattern::Plunge, stock, {2.0, 1.0, 10.0}, 1.0, 1.0, 0, [](double, double) { return 0.0; });
  int plunges = 0;
  for (const Vector3d& point : script.device_mm) {
    if (point.z() < 0.0) {
      DOUBLES_EQUAL(-1.0, point.z(), 0.0);
      ++plunges;
    }
  }
  LONGS_EQUAL(2, plunges);  // x = 1 and 3, y = 1
}

TEST(OperatorScript, TheHandSettlesWhereItsSpringBalancesTheRenderedForce) {
  OperatorHand hand;
  hand.stiffness_n_per_mm = 2.0;
  hand.step({1.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  DOUBLES_EQUAL(0.3, hand.handle_mm.x(), 1e-12);  // a fraction of the way, not all of it
  for (int ms = 0; ms < 200; ++ms) hand.step({1.0, 0.0, 0.0}, {0.0, 0.0, 4.0});
  check_vector({1.0, 0.0, 2.0}, hand.handle_mm, 1e-9);  // 4 N against 2 N/mm: 2 mm off the script
}
