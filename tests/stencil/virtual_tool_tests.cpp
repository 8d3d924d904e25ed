// The virtual tool against an independent oracle: whatever the device does, the ball end mill never
// cuts into the true part surface by more than the table's undetectable-gouge bound.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "firmware/core/stencil/sweep.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/loaded_part.hpp"
#include "tests/support/sample_tables.hpp"
#include "tests/support/gouge_oracle.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::engine;

namespace {

const Eigen::Vector3d kHome(25.0, 12.5, 20.0);  // above every sample part


struct Loaded : test::LoadedPart {
  explicit Loaded(const std::vector<tablegen::Facet>& facets) : test::LoadedPart(facets) { CHECK(loaded); }
};

// Drives the virtual tool through `path` and checks every cycle against the oracle.
void check_never_gouges(const tables::PartTables& part, const std::vector<Eigen::Vector3d>& path, double& worst) {
  VirtualTool tool(part, kHome);
  const ContactParameters parameters{};
  for (const Eigen::Vector3d& desired : path) {
    const RemediationResult result = tool.step(desired, parameters);
    CHECK(result.status != RemediationStatus::Fault);
    CHECK(check_legal(part, tool.pose()) == Legality::Legal);
    CHECK(tool.tip_mm().z() >= 0.0);
    const double gouge = test::ball_end_gouge_mm(part, tool.tip_mm());
    worst = std::max(worst, gouge);
    CHECK(gouge <= part.header.gouge_bound_mm + 1e-5);
  }
}

std::vector<Eigen::Vector3d> random_walk(std::mt19937_64& random, int cycles, double step_mm) {
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::uniform_real_distribution<double> box(0.0, 1.0);
  std::vector<Eigen::Vector3d> path;
  Eigen::Vector3d at(50.0 * box(random), 25.0 * box(random), 10.0 * box(random));
  for (int i = 0; i < cycles; ++i) {
    at += step_mm * Eigen::Vector3d(gaussian(random), gaussian(random), gaussian(random));
    at = at.cwiseMax(Eigen::Vector3d(-2, -2, -2)).cwiseMin(Eigen::Vector3d(52, 27, 15));
    path.push_back(at);
  }
  return path;
}

}  // namespace

TEST_GROUP(VirtualTool){};

TEST(VirtualTool, NeverGougesTheTruePartOnRandomAndAdversarialPaths) {
  std::mt19937_64 random(51);
  for (const auto& facets : {tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5),
                             tablegen::slotted_block(30.0, 12.0, 6.0, 2.0, 3.0, 10.0, 6.5),
                             tablegen::thin_fin(20.0, 0.6, 8.0, 15.0, 12.2)}) {
    const Loaded loaded(facets);
    double worst = 0.0;
    for (int walk = 0; walk < 12; ++walk) {
      check_never_gouges(loaded.part, random_walk(random, 120, walk % 2 == 0 ? 0.05 : 0.8), worst);
    }
    // Plunges straight down through the part from above, and a device parked far inside it.
    std::vector<Eigen::Vector3d> plunge;
    for (double z = 12.0; z > -3.0; z -= 0.3) plunge.push_back({25.2, 12.4, z});
    for (int i = 0; i < 20; ++i) plunge.push_back({25.0, 12.5, 1.0});
    check_never_gouges(loaded.part, plunge, worst);
    // Fast sweeps along x at heights through the part, each cycle a large jump.
    std::vector<Eigen::Vector3d> sweep;
    for (double z : {7.0, 4.0, 1.0}) {
      for (double x = 2.0; x < 48.0; x += 3.0) sweep.push_back({x, 12.5, z});
      for (double x = 48.0; x > 2.0; x -= 3.0) sweep.push_back({x, 12.9, z});
    }
    check_never_gouges(loaded.part, sweep, worst);
  }
}

TEST(VirtualTool, AJumpStraightThroughTheThinFinInOneCycleIsStoppedAtTheFin) {
  const Loaded loaded(tablegen::thin_fin(20.0, 0.6, 8.0, 15.0, 12.2));  // fin y in [12.2, 12.8]
  VirtualTool tool(loaded.part, {25.0, 8.0, 2.0});
  const RemediationResult result = tool.step({25.0, 17.0, 2.0}, ContactParameters{});
  CHECK(result.status == RemediationStatus::Blocked || result.status == RemediationStatus::Stuck);
  CHECK(tool.tip_mm().y() < 12.2 - 1.5 + 1e-3);  // still on the near side, the cutter short of the fin
  double worst = 0.0;
  check_never_gouges(loaded.part, {{25.0, 17.0, 2.0}, {25.0, 17.0, 2.0}, {25.0, 20.0, 2.0}}, worst);
}

TEST(VirtualTool, SlipsAlongAFaceInsteadOfStickingAtTheEntryPoint) {
  const Loaded loaded(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  VirtualTool tool(loaded.part, {20.0, 12.5, 7.0});
  const ContactParameters parameters{};
  // Drag the device 0.2 mm into the top face from x = 20 to x = 30.
  for (double x = 20.0; x <= 30.0; x += 0.05) {
    static_cast<void>(tool.step({x, 12.5, 5.8}, parameters));
  }
  // The tool followed along the face (not stuck near x = 20), riding on it, not in it.
  DOUBLES_EQUAL(30.0, tool.tip_mm().x(), 0.06);
  CHECK(tool.tip_mm().z() >= 6.0 - loaded.part.header.gouge_bound_mm - 1e-5);
  CHECK(tool.tip_mm().z() <= 6.0 + 0.01);
}

TEST(VirtualTool, PushedIntoAConcaveCornerItSlipsOutToBothFacesWithinTwoSlips) {
  // A slot wide enough for the 3 mm ball: its floor (z = 3) meets its wall (y = 9.5) in a corner.
  const Loaded loaded(tablegen::slotted_block(30.0, 12.0, 6.0, 6.0, 3.0, 10.0, 6.5));
  VirtualTool tool(loaded.part, {25.0, 12.5, 3.5});
  // 0.5 mm into the floor and into the wall at once: the reaction is about the corner's bisector,
  // and the slip clears the deepest point measured along it (0.5 / cos 45). Moving by 0.5 along
  // it clears each face by only 0.35 mm at a time: three slips here, five in the bench's corner.
  // The second slip mends what the reaction's lean towards one face left.
  const RemediationResult result = tool.step({25.0, 10.5, 2.5}, ContactParameters{});
  CHECK(result.status == RemediationStatus::Slipped);
  CHECK(result.slip_iterations >= 1 && result.slip_iterations <= 2);
  CHECK(check_legal(loaded.part, tool.pose()) == Legality::Legal);
  CHECK(test::ball_end_gouge_mm(loaded.part, tool.tip_mm()) <= loaded.part.header.gouge_bound_mm + 1e-5);
  // Resting against both faces: 1.5 mm (the ball's radius) from the wall, its tip on the floor.
  // Not moved along the slot, to well under a micrometre: leaves deep in the part are settled from
  // their moments or their groups' (the reaction's direction within half a degree of the points'
  // own), which need not be symmetric about x = 25 (measured: 0.43 um; allowed 5 um, half the
  // other two checks').
  DOUBLES_EQUAL(25.0, tool.tip_mm().x(), 5e-3);
  DOUBLES_EQUAL(11.0, tool.tip_mm().y(), 0.01);
  DOUBLES_EQUAL(3.0, tool.tip_mm().z(), 0.01);
}

TEST(VirtualTool, WhereTheStraightWayCutsACornerItSlidesRoundTheCornerInsteadOfSticking) {
  // The hex prism's vertex at (33, 12.5), its walls receding on both sides. The tool rests against
  // the vertex from the +x side, low enough for its side to meet it; the hand goes round to a legal
  // point beyond, so the straight line from the tool cuts through the vertex.
  const Loaded loaded(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  const double radius = loaded.part.tool.envelope.cutter_radius_mm;
  VirtualTool tool(loaded.part, {33.0 + radius + 0.05, 13.2, 2.0});
  CHECK(check_legal(loaded.part, tool.pose()) == Legality::Legal);
  const Eigen::Vector3d beyond(33.0 + radius - 0.2, 10.0, 2.0);  // legal: the wall has receded there
  CHECK(check_tip_legal(loaded.part, beyond) == Legality::Legal);
  CHECK(check_sweep(loaded.part, tool.tip_mm(), beyond, tool.sweep_step_mm(), kMaxSweepSteps).status ==
        SweepStatus::Illegal);
  int stuck = 0;
  for (int i = 0; i < 400 && (tool.tip_mm() - beyond).norm() > 1e-9; ++i) {
    const Eigen::Vector3d before = tool.tip_mm();
    const RemediationResult result = tool.step(beyond, ContactParameters{});
    stuck += result.status == RemediationStatus::Stuck ? 1 : 0;
    CHECK(check_legal(loaded.part, tool.pose()) == Legality::Legal);
    CHECK(test::ball_end_gouge_mm(loaded.part, tool.tip_mm()) <= loaded.part.header.gouge_bound_mm + 1e-5);
    // Every move it made was itself a checked straight sweep.
    CHECK(check_sweep(loaded.part, before, tool.tip_mm(), tool.sweep_step_mm(), kMaxSweepSteps).status !=
          SweepStatus::Illegal);
  }
  LONGS_EQUAL(0, stuck);
  CHECK((tool.tip_mm() - beyond).norm() < 1e-9);  // it got round
}

TEST(VirtualTool, WithASpeedLimitItMovesNoFasterThanTheMillAndStaysLegal) {
  const Loaded loaded(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  VirtualTool tool(loaded.part, {20.0, 12.5, 7.0});
  tool.limit_speed(0.0014, 0.0015);  // per cycle: 1.4 mm/s per axis, 1.5 mm/s all axes together
  int limited = 0;
  // Far, fast, and into the part: the tool creeps along at the limit, slips included.
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d before = tool.tip_mm();
    const RemediationResult result = tool.step({30.0, 14.0, 5.0}, ContactParameters{});
    const Eigen::Vector3d move = (tool.tip_mm() - before).cwiseAbs();
    // Rounding slack: the tip's coordinates are tens of mm, whose last bit is about 4e-15 mm, and
    // the move is rounded once going out and once measured back here.
    constexpr double kRounding_mm = 1e-13;
    CHECK(move.maxCoeff() <= 0.0014 + kRounding_mm);
    CHECK(move.sum() <= 0.0015 + kRounding_mm);
    CHECK(check_legal(loaded.part, tool.pose()) == Legality::Legal);
    limited += result.speed_limited ? 1 : 0;
  }
  CHECK(limited > 2000);
  CHECK(tool.tip_mm().x() > 22.0);  // and it did get somewhere
}

TEST(VirtualTool, NeverGoesBelowTheFloorOrOutOfTheWorkspace) {
  const Loaded loaded(tablegen::thin_fin(20.0, 0.6, 8.0, 15.0, 12.2));
  VirtualTool tool(loaded.part, {5.0, 5.0, 5.0});
  for (const Eigen::Vector3d& desired : {Eigen::Vector3d(5, 5, -3), Eigen::Vector3d(-4, 5, 2), Eigen::Vector3d(60, 30, 40)}) {
    for (int i = 0; i < 50; ++i) {
      static_cast<void>(tool.step(desired, ContactParameters{}));
    }
    CHECK((tool.tip_mm().array() >= 0.0).all());
    CHECK((tool.tip_mm().array() <= Eigen::Array3d(50.0, 25.0, 25.0)).all());
  }
  DOUBLES_EQUAL(50.0, tool.tip_mm().x(), 1e-9);
}

TEST(VirtualTool, TheSameInputsGiveBitIdenticalOutputs) {
  const Loaded loaded(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  std::mt19937_64 random(52);
  const auto path = random_walk(random, 200, 0.3);
  VirtualTool a(loaded.part, kHome);
  VirtualTool b(loaded.part, kHome);
  for (const Eigen::Vector3d& desired : path) {
    const RemediationResult ra = a.step(desired, ContactParameters{});
    const RemediationResult rb = b.step(desired, ContactParameters{});
    CHECK(ra.tip_mm == rb.tip_mm);
    CHECK(ra.status == rb.status);
  }
}

TEST(VirtualTool, ANonFiniteDesiredPoseIsAFaultAndTheToolStays) {
  const Loaded loaded(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  VirtualTool tool(loaded.part, kHome);
  const RemediationResult result = tool.step({std::numeric_limits<double>::quiet_NaN(), 1.0, 1.0}, ContactParameters{});
  CHECK(result.status == RemediationStatus::Fault);
  CHECK(tool.tip_mm() == kHome);
}
