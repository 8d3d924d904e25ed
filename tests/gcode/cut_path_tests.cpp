// The legs the mill was commanded, from its recorded targets, and their merging: a merge that
// leaves the recorded corners is made only where the engine's sweep finds it legal.
#include <cmath>
#include <string>
#include <vector>

#include "firmware/core/stencil/sweep.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/gcode/cut_path.hpp"
#include "tests/support/sample_tables.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using gcode::CutMove;
using gcode::CutPath;
using gcode::MoveKind;

namespace {

const Eigen::Vector3d kHome(50.0, 25.0, 25.0);

control::MachineCommandRecord target(double x, double y, double z, std::uint8_t a = 0, std::uint8_t b = 1, std::uint8_t c = 2) {
  static std::uint64_t update = 0;
  return {++update, 0, {}, {a, b, c}, {x, y, z}};
}

CutPath staircase() {
  CutPath path({motion::MachinePath::Staircase, kHome, 0.1});
  path.homed();
  return path;
}

void check_point(const Eigen::Vector3d& expected, const Eigen::Vector3d& actual) {
  DOUBLES_EQUAL(expected.x(), actual.x(), 1e-12);
  DOUBLES_EQUAL(expected.y(), actual.y(), 1e-12);
  DOUBLES_EQUAL(expected.z(), actual.z(), 1e-12);
}

}  // namespace

TEST_GROUP(CutPath){};

TEST(CutPath, StaircaseLegsGoInTheRecordedOrderAndShareTheUpdatesTime) {
  CutPath path = staircase();
  std::string error;
  CHECK(path.command(target(49.0, 24.0, 22.0, 2, 0, 1), error));  // Z, then X, then Y
  const std::vector<CutMove>& moves = path.moves();
  LONGS_EQUAL(3, moves.size());
  check_point({50.0, 25.0, 22.0}, moves[0].to_mm);
  check_point({49.0, 25.0, 22.0}, moves[1].to_mm);
  check_point({49.0, 24.0, 22.0}, moves[2].to_mm);
  DOUBLES_EQUAL(0.1 * 3.0 / 5.0, moves[0].seconds, 1e-12);  // 3 of the update's 5 mm
  DOUBLES_EQUAL(0.1 * 1.0 / 5.0, moves[1].seconds, 1e-12);
  CHECK(moves[0].kind == MoveKind::Feed);
}

TEST(CutPath, AnAxisThatDoesNotMoveMakesNoLeg) {
  CutPath path = staircase();
  std::string error;
  CHECK(path.command(target(50.0, 24.5, 25.0), error));
  LONGS_EQUAL(1, path.moves().size());
  DOUBLES_EQUAL(0.1, path.moves()[0].seconds, 1e-12);
}

TEST(CutPath, ATakeUpMovesNothing) {
  CutPath path = staircase();
  std::string error;
  CHECK(path.command(target(50.0, 24.5, 25.0), error));
  CHECK(path.command(target(50.0, 24.5, 25.0), error));  // the motors take up the slack; the tool stands
  LONGS_EQUAL(1, path.moves().size());
  LONGS_EQUAL(2, path.targets());
}

TEST(CutPath, AStraightMachineMovesInOneSegment) {
  CutPath path({motion::MachinePath::Straight, kHome, 0.125});
  path.homed();
  std::string error;
  CHECK(path.command(target(49.0, 24.0, 22.0, 2, 0, 1), error));
  LONGS_EQUAL(1, path.moves().size());
  check_point({49.0, 24.0, 22.0}, path.moves()[0].to_mm);
  DOUBLES_EQUAL(0.125, path.moves()[0].seconds, 1e-12);
}

TEST(CutPath, AHomingAfterACutRetractsStraightUpThenGoesAcross) {
  CutPath path = staircase();
  std::string error;
  CHECK(path.command(target(40.0, 20.0, 10.0), error));
  path.homed();  // a resumed job: the machine homed again
  const std::vector<CutMove>& moves = path.moves();
  LONGS_EQUAL(5, moves.size());
  CHECK(moves[3].kind == MoveKind::Traverse);
  check_point({40.0, 20.0, 25.0}, moves[3].to_mm);
  check_point(kHome, moves[4].to_mm);
}

TEST(CutPath, ATargetBeforeHomingOrNotFiniteIsRefusedNamingIt) {
  CutPath path({motion::MachinePath::Staircase, kHome, 0.1});
  std::string error;
  CHECK_FALSE(path.command(target(1.0, 2.0, 3.0), error));
  CHECK(error.find("before the machine was homed") != std::string::npos);
  path.homed();
  CHECK_FALSE(path.command(target(1.0, std::nan(""), 3.0), error));
  CHECK(error.find("not a finite point") != std::string::npos);
  LONGS_EQUAL(0, path.moves().size());
}

TEST(CutPath, AStaircaseOrderThatLeavesOutAMovingAxisIsRefusedNamingTheTarget) {
  CutPath path = staircase();
  std::string error;
  // Y moves, but the order is X, Z, none: no staircase the mill can have moved.
  const control::MachineCommandRecord record = target(49.0, 24.0, 25.0, 0, 2, 3);
  CHECK_FALSE(path.command(record, error));
  CHECK(error.find("machine target " + std::to_string(record.update)) != std::string::npos);
  CHECK(error.find("leaves out") != std::string::npos);
  LONGS_EQUAL(0, path.moves().size());
  LONGS_EQUAL(0, path.targets());
}

namespace {

struct Part {
  tablegen::TableBytes bytes;
  tables::PartTables part{};
  Part() : bytes(test::make_table(test::default_part(), test::default_job_options(2))) {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  }
  // The lowest legal tip over (x, y), to 1e-6 mm.
  [[nodiscard]] double lowest_tip(double x, double y) const {
    double low = 0.0, high = 25.0;
    while (high - low > 1e-6) {
      const double mid = 0.5 * (low + high);
      (engine::check_tip_legal(part, {x, y, mid}) == engine::Legality::Legal ? high : low) = mid;
    }
    return high;
  }
  // The part's top centre (x, y) from its triangles.
  [[nodiscard]] Eigen::Vector3d top_centre() const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double top = -1e9;
    for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
      for (const tables::PackedPoint& v : part.triangles[t].vertices) {
        sum += Eigen::Vector3d(v.x_mm, v.y_mm, v.z_mm);
        top = std::max(top, static_cast<double>(v.z_mm));
      }
    }
    sum /= 3.0 * part.triangle_count();
    return {sum.x(), sum.y(), top};
  }
};

std::vector<CutMove> feeds(const std::vector<Eigen::Vector3d>& points, double seconds_per_mm, const Eigen::Vector3d& start) {
  std::vector<CutMove> moves;
  Eigen::Vector3d at = start;
  for (const Eigen::Vector3d& p : points) {
    moves.push_back({MoveKind::Feed, p, seconds_per_mm * (p - at).norm()});
    at = p;
  }
  return moves;
}

}  // namespace

TEST_GROUP(MergeCollinear){};

TEST(MergeCollinear, ARunAlongOneLineAtOneSpeedBecomesOneMoveOfTheSameTime) {
  const Part p;
  const Eigen::Vector3d start(45.0, 20.0, 24.0);  // high above the part
  std::vector<Eigen::Vector3d> points;
  for (int i = 1; i <= 10; ++i) {
    points.emplace_back(45.0 - 0.1 * i, 20.0, 24.0);
  }
  const gcode::MergeResult merged = gcode::merge_collinear(feeds(points, 2.0, start), start, p.part, 0.0);
  LONGS_EQUAL(1, merged.moves.size());
  check_point(points.back(), merged.moves[0].to_mm);
  DOUBLES_EQUAL(2.0, merged.moves[0].seconds, 1e-9);
  LONGS_EQUAL(9, merged.merged_away);
  LONGS_EQUAL(0, merged.sweep_checks);  // on the recorded path: nothing new to check
}

TEST(MergeCollinear, ASpeedChangeOrACornerEndsTheRun) {
  const Part p;
  const Eigen::Vector3d start(45.0, 20.0, 24.0);
  std::vector<CutMove> moves = feeds({{44.0, 20.0, 24.0}, {43.0, 20.0, 24.0}}, 2.0, start);
  moves.push_back({MoveKind::Feed, {42.0, 20.0, 24.0}, 1.5});                // 25 % slower
  moves.push_back({MoveKind::Feed, {42.0, 19.0, 24.0}, 1.5});                // a corner
  const gcode::MergeResult merged = gcode::merge_collinear(moves, start, p.part, 0.001);
  LONGS_EQUAL(3, merged.moves.size());
  check_point({43.0, 20.0, 24.0}, merged.moves[0].to_mm);
}

TEST(MergeCollinear, CornersFartherThanTheToleranceAreKept) {
  const Part p;
  const Eigen::Vector3d start(45.0, 20.0, 24.0);
  const std::vector<CutMove> moves = feeds({{44.0, 20.0, 24.002}, {43.0, 20.0, 24.0}}, 2.0, start);
  LONGS_EQUAL(2, gcode::merge_collinear(moves, start, p.part, 0.001).moves.size());
  LONGS_EQUAL(1, gcode::merge_collinear(moves, start, p.part, 0.003).moves.size());
}

// Over the part's rim the legal tips make a hump (the ball rolls over the edge): a chord across it
// dips into the part although every corner it drops is within the tolerance of it. The sweep refuses
// that merge; the same corners lifted clear of the part merge.
TEST(MergeCollinear, AMergeOffThePathIntoThePartIsRefusedByTheSweep) {
  const Part p;
  const Eigen::Vector3d centre = p.top_centre();
  // Out along +x from the centre to where the tip starts to drop: the rim.
  double rim = centre.x();
  while (p.lowest_tip(rim + 0.05, centre.y()) > centre.z() - 0.01) {
    rim += 0.05;
  }
  std::vector<Eigen::Vector3d> hump;
  for (const double dx : {-0.3, 0.0, 0.3}) {
    hump.emplace_back(rim + dx, centre.y(), p.lowest_tip(rim + dx, centre.y()) + 1e-4);
  }
  for (const Eigen::Vector3d& corner : hump) {
    CHECK(engine::check_tip_legal(p.part, corner) == engine::Legality::Legal);
  }
  const std::vector<CutMove> moves = feeds({hump[1], hump[2]}, 2.0, hump[0]);
  const gcode::MergeResult over_the_rim = gcode::merge_collinear(moves, hump[0], p.part, 0.1);
  LONGS_EQUAL(2, over_the_rim.moves.size());
  LONGS_EQUAL(1, over_the_rim.sweep_checks);
  const Eigen::Vector3d up(0.0, 0.0, 5.0);
  const std::vector<CutMove> lifted = feeds({hump[1] + up, hump[2] + up}, 2.0, hump[0] + up);
  LONGS_EQUAL(1, gcode::merge_collinear(lifted, hump[0] + up, p.part, 0.1).moves.size());
}

TEST(MergeCollinear, TraversesAreNeverMerged) {
  const Part p;
  const Eigen::Vector3d start(45.0, 20.0, 24.0);
  const std::vector<CutMove> moves{{MoveKind::Traverse, {44.0, 20.0, 24.0}, 0.0}, {MoveKind::Traverse, {43.0, 20.0, 24.0}, 0.0}};
  LONGS_EQUAL(2, gcode::merge_collinear(moves, start, p.part, 0.001).moves.size());
}
