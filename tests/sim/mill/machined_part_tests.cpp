// The stock's Z-map and the ground truth of a cut: heights under a ball end mill's pass, what it
// leaves beside it, and the gouge of a swept cutter against the part's own triangles.
#include <cmath>
#include <memory>

#include "firmware/core/tables/table_loader.hpp"
#include "sim/mill/machined_part.hpp"
#include "sim/mill/stock_zmap.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::sim;

namespace {

const ToolProfile kBall{geometry::CutterKind::Ball, 1.5, 0.0};

}  // namespace

TEST_GROUP(StockZmap){};

TEST(StockZmap, TheToolProfileIsTheCuttersLowerSurface) {
  DOUBLES_EQUAL(0.0, kBall.height_at(0.0), 0.0);
  DOUBLES_EQUAL(1.5 - std::sqrt(1.5 * 1.5 - 1.0), kBall.height_at(1.0), 1e-12);
  DOUBLES_EQUAL(1.5, kBall.height_at(1.5), 1e-12);
  CHECK(std::isinf(kBall.height_at(1.6)));
  const ToolProfile flat{geometry::CutterKind::Flat, 1.5, 0.0};
  DOUBLES_EQUAL(0.0, flat.height_at(1.4), 0.0);
  const ToolProfile bull{geometry::CutterKind::BullNose, 2.0, 0.5};
  DOUBLES_EQUAL(0.0, bull.height_at(1.5), 0.0);
  DOUBLES_EQUAL(0.5 - std::sqrt(0.25 - 0.09), bull.height_at(1.8), 1e-12);
}

TEST(StockZmap, APassAlongXCutsAChannelOfTheBallsProfileAndLeavesTheRest) {
  StockZmap stock({{0.0, 0.0, 0.0}, {10.0, 6.0, 5.0}}, 0.05);
  stock.cut({2.0, 3.0, 4.0}, {8.0, 3.0, 4.0}, kBall);
  for (int column = 0; column < stock.columns(); ++column) {
    for (int row = 0; row < stock.rows(); ++row) {
      const Eigen::Vector2d c = stock.centre(column, row);
      const double dx = c.x() < 2.0 ? 2.0 - c.x() : (c.x() > 8.0 ? c.x() - 8.0 : 0.0);
      const double distance = std::hypot(dx, c.y() - 3.0);
      const double expected = std::min(5.0, 4.0 + kBall.height_at(distance));
      DOUBLES_EQUAL(expected, stock.height(column, row), 1e-12);
    }
  }
  // The channel: 6 mm of the ball's circle below the stock's top (a segment 0.5 mm below the centre
  // at z = 5.5), and the two half-ball ends, which make one sphere cap of height 1 mm.
  const double radius = 1.5, below_centre = 0.5, cap_height = 1.0;
  const double segment = radius * radius * std::acos(below_centre / radius) -
                         below_centre * std::sqrt(radius * radius - below_centre * below_centre);
  const double cap = 3.14159265358979323846 * cap_height * cap_height * (3.0 * radius - cap_height) / 3.0;
  DOUBLES_EQUAL(6.0 * segment + cap, stock.removed_volume_mm3(), 0.01 * (6.0 * segment + cap));
}

TEST(StockZmap, AVerticalMoveCutsWhereItsLowestPointIs) {
  StockZmap stock({{0.0, 0.0, 0.0}, {6.0, 6.0, 5.0}}, 0.05);
  stock.cut({3.0, 3.0, 6.0}, {3.0, 3.0, 2.5}, kBall);
  const int column = static_cast<int>(3.0 / stock.cell_mm());
  DOUBLES_EQUAL(2.5 + kBall.height_at((stock.centre(column, column) - Eigen::Vector2d(3.0, 3.0)).norm()),
                stock.height(column, column), 1e-12);
  DOUBLES_EQUAL(5.0, stock.height(0, 0), 0.0);
}

TEST(StockZmap, NothingIsCutBelowTheFloor) {
  StockZmap stock({{0.0, 0.0, 0.0}, {6.0, 6.0, 5.0}}, 0.05);
  stock.cut({3.0, 3.0, -2.0}, {4.0, 3.0, -2.0}, kBall);
  const int column = static_cast<int>(3.0 / stock.cell_mm());
  DOUBLES_EQUAL(0.0, stock.height(column, column), 0.0);
}

// The hex prism's tables, and a machined part over its stock whose frames put step 0 at the world
// origin, so that world = steps / 640 on every axis.
struct PrismJob {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  std::unique_ptr<MachinedPart> machined;
  PrismJob() {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    const motion::MachineFrames frames{10.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {1, 1, 1}, 640.0};
    machined = std::make_unique<MachinedPart>(part, StockBox{{15.0, 3.0, 0.0}, {35.0, 22.0, 7.0}}, frames,
                                              [] { return 0.0; });
    machined->arm({0, 0, 0});
  }
  static std::array<std::int64_t, 3> at(double x, double y, double z) {
    return {std::llround(x * 640.0), std::llround(y * 640.0), std::llround(z * 640.0)};
  }
};

// From the origin (far from the prism) along y, up to z = 5.75, then along x across the prism's
// middle: the tip is 0.25 mm into its top face (z = 6) there, a gouge of 0.25 mm.
static void gouge_the_prisms_top(MachinedPart& machined) {
  const auto at = &PrismJob::at;
  machined.axis_moved(Axis::y, at(0.0, 12.5, 0.0));
  machined.axis_moved(Axis::z, at(0.0, 12.5, 5.75));
  machined.axis_moved(Axis::x, at(25.0, 12.5, 5.75));
  machined.flush();
}

TEST_GROUP(MachinedPart){};

TEST(MachinedPart, ALegThatCutsIntoThePrismIsAGougeOfItsDepth) {
  PrismJob job;
  MachinedPart& machined = *job.machined;
  gouge_the_prisms_top(machined);
  DOUBLES_EQUAL(0.25, machined.max_gouge_mm(), 0.002);
  CHECK(machined.gouge_measured());
}

TEST(MachinedPart, ALegClearOfThePartIsNoGouge) {
  PrismJob job;
  MachinedPart& machined = *job.machined;
  const auto at = &PrismJob::at;
  machined.axis_moved(Axis::z, at(0.0, 0.0, 6.01));
  machined.axis_moved(Axis::x, at(25.0, 0.0, 6.01));
  machined.axis_moved(Axis::y, at(25.0, 12.5, 6.01));  // over the top, 10 um clear
  machined.flush();
  DOUBLES_EQUAL(0.0, machined.max_gouge_mm(), 0.0);
  LONGS_EQUAL(3, machined.legs());
}

TEST(MachinedPart, EachCellsSignedDistanceIsFromItsTopToThePrismsSurface) {
  PrismJob job;
  MachinedPart& machined = *job.machined;
  gouge_the_prisms_top(machined);
  const StockZmap& stock = machined.stock();
  const std::vector<float> distance = machined.signed_distances(machined.part_heights(), 2.0);
  LONGS_EQUAL(static_cast<long>(stock.columns()) * stock.rows(), static_cast<long>(distance.size()));
  const auto cell = [&](double x, double y) {
    const int column = static_cast<int>((x - 15.0) / stock.cell_mm()), row = static_cast<int>((y - 3.0) / stock.cell_mm());
    return distance[static_cast<std::size_t>(row) * static_cast<std::size_t>(stock.columns()) + static_cast<std::size_t>(column)];
  };
  // Untouched over the prism's top (z = 6): the stock's top 1 mm above it.
  DOUBLES_EQUAL(1.0, cell(26.0, 16.0), 1e-4);
  // Under the leg, 3 mm inside the prism's side: 0.25 mm under its top (the ball's centre line is
  // 0.2 um off the cell's centre).
  DOUBLES_EQUAL(-0.25, cell(20.0, 12.5), 1e-3);
  // The stock's corner, farther than the reach from the prism: clamped to it.
  DOUBLES_EQUAL(2.0, cell(15.1, 3.1), 0.0);
}
