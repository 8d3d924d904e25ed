// The stock's Z-map: the cutter's lower surface, heights under a ball end mill's pass and what it
// leaves beside it, the x-y-z staircase of a move along several axes, the floor, the cells' size.
#include <cmath>

#include "firmware/core/geometry/tool_spec.hpp"
#include "sim/mill/stock_zmap.hpp"

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
TEST(StockZmap, AToolProfileTakesTheSpecsRadiusAndACornerRadiusOnlyForABullNose) {
  const ToolProfile ball = ToolProfile::of({geometry::CutterKind::Ball, 3.0, 10.0, 0.7, 3.0, 20.0});
  DOUBLES_EQUAL(1.5, ball.radius_mm, 0.0);
  DOUBLES_EQUAL(0.0, ball.corner_radius_mm, 0.0);
  const ToolProfile bull = ToolProfile::of({geometry::CutterKind::BullNose, 4.0, 10.0, 0.5, 4.0, 20.0});
  DOUBLES_EQUAL(2.0, bull.radius_mm, 0.0);
  DOUBLES_EQUAL(0.5, bull.corner_radius_mm, 0.0);
}

TEST(StockZmap, CellsAreSquareAndNoLargerThanAsked) {
  const StockZmap stock({{0.0, 0.0, 0.0}, {10.0, 6.0, 5.0}}, 0.07);
  LONGS_EQUAL(143, stock.columns());  // ceil(10 / 0.07)
  LONGS_EQUAL(86, stock.rows());      // ceil(6 / 0.07)
  DOUBLES_EQUAL(10.0 / 143.0, stock.cell_mm(), 1e-15);  // the larger of 10/143 and 6/86
  DOUBLES_EQUAL(5.0, stock.height(142, 85), 0.0);        // every cell starts full
  DOUBLES_EQUAL(0.0, stock.removed_volume_mm3(), 0.0);
}

TEST(StockZmap, AMoveAlongSeveralAxesIsCutAsTheStaircaseXThenYThenZ) {
  StockZmap stock({{0.0, 0.0, 0.0}, {6.0, 6.0, 5.0}}, 0.05);
  const ToolProfile flat{geometry::CutterKind::Flat, 0.5, 0.0};
  stock.cut({1.0, 1.0, 3.0}, {5.0, 5.0, 3.0}, flat);
  const auto at = [&stock](double x, double y) {
    return stock.height(static_cast<int>(x / stock.cell_mm()), static_cast<int>(y / stock.cell_mm()));
  };
  DOUBLES_EQUAL(3.0, at(5.0, 1.0), 0.0);  // the staircase's corner: along x first
  DOUBLES_EQUAL(3.0, at(3.0, 1.0), 0.0);
  DOUBLES_EQUAL(3.0, at(5.0, 3.0), 0.0);
  DOUBLES_EQUAL(5.0, at(1.0, 5.0), 0.0);  // the other corner is never visited
  DOUBLES_EQUAL(5.0, at(3.0, 3.0), 0.0);  // nor the diagonal
}

TEST(StockZmap, AMoveAboveTheStockCutsNothing) {
  StockZmap stock({{0.0, 0.0, 0.0}, {6.0, 6.0, 5.0}}, 0.05);
  stock.cut({0.0, 3.0, 5.0}, {6.0, 3.0, 5.0}, kBall);
  stock.cut({3.0, 0.0, 7.0}, {3.0, 6.0, 7.0}, kBall);
  DOUBLES_EQUAL(0.0, stock.removed_volume_mm3(), 0.0);
}
