// The controller's model of the machined stock: the tool's true shape pressed along each leg, the
// floor kept, nothing outside the footprint touched, bad inputs refused.
#include <cmath>
#include <limits>
#include <vector>

#include "firmware/core/control/commanded_stock.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::CommandedStock;
using stencil::control::StockBlock;
using stencil::geometry::CutterKind;
using stencil::geometry::ToolSpec;

namespace {

constexpr double kCell = 0.05;
const StockBlock kBlock{{10.0, 5.0, 0.0}, {20.0, 15.0, 6.0}};

ToolSpec tool(CutterKind kind, double diameter, double corner = 0.0) { return {kind, diameter, 12.0, corner, 6.0, 20.0}; }

struct Model {
  std::vector<float> cells;
  CommandedStock stock;
  explicit Model(const ToolSpec& t)
      : cells(CommandedStock::cells_needed(kBlock, kCell)), stock(kBlock, kCell, t, cells) {}
  // The height over the cell whose centre is nearest (x, y).
  [[nodiscard]] double at(double x, double y) const {
    return stock.height(static_cast<int>((x - kBlock.low_mm.x()) / kCell), static_cast<int>((y - kBlock.low_mm.y()) / kCell));
  }
};

}  // namespace

TEST_GROUP(CommandedStock){};

TEST(CommandedStock, ABallEndPassLeavesTheBallsProfileAcrossItAndTheFullBlockBeyondIt) {
  Model model(tool(CutterKind::Ball, 3.0));
  CHECK_TRUE(model.stock.ready());
  LONGS_EQUAL(200, model.stock.columns());
  LONGS_EQUAL(200, model.stock.rows());
  model.stock.cut({12.0, 10.025, 4.0}, {18.0, 10.025, 4.0});  // along x, over cell centres in y
  // The pass is pressed in at points a cell apart: half a cell from one, the ball is 0.2 um higher.
  constexpr double kBetweenPoints = 3e-4;
  DOUBLES_EQUAL(4.0, model.at(15.0, 10.0), kBetweenPoints);
  for (const double off : {0.5, 1.0, 1.4}) {
    const double y = 10.025 + off;
    const double expected = 4.0 + 1.5 - std::sqrt(1.5 * 1.5 - off * off);
    DOUBLES_EQUAL(expected, model.at(15.0, y), kBetweenPoints + 1e-3 * off);
  }
  DOUBLES_EQUAL(6.0, model.at(15.0, 10.025 + 1.6), 0.0);   // beyond the radius: untouched
  DOUBLES_EQUAL(6.0, model.at(19.7, 10.0), 0.0);           // past the end of the pass
  DOUBLES_EQUAL(4.0, model.at(18.0, 10.0), kBetweenPoints);  // the end point itself is cut
  const double width = 2.0 * 1.5;
  CHECK(model.stock.removed_volume_mm3() > 6.0 * width * 0.5);  // at least the pass's lower half
  CHECK(model.stock.removed_volume_mm3() < (6.0 + width) * width * 2.0);
}

TEST(CommandedStock, TheFloorIsKeptWhereTheTipGoesBelowIt) {
  Model model(tool(CutterKind::Flat, 2.0));
  model.stock.cut({15.0, 10.0, 3.0}, {15.0, 10.0, -2.0});
  DOUBLES_EQUAL(0.0, model.at(15.0, 10.0), 0.0);
  DOUBLES_EQUAL(0.0, model.at(15.9, 10.0), 0.0);  // a flat end cuts its whole disc flat
  DOUBLES_EQUAL(6.0, model.at(16.1, 10.0), 0.0);
}

TEST(CommandedStock, ABullNoseIsFlatInsideItsCornerAndRoundInIt) {
  Model model(tool(CutterKind::BullNose, 4.0, 1.0));
  model.stock.cut({15.025, 10.025, 2.0}, {15.025, 10.025, 2.0});
  DOUBLES_EQUAL(2.0, model.at(15.025 + 0.9, 10.025), 1e-5);
  const double off = 1.5 - 1.0;  // half a millimetre into the corner
  DOUBLES_EQUAL(2.0 + 1.0 - std::sqrt(1.0 - off * off), model.at(15.025 + 1.5, 10.025), 1e-5);
}

TEST(CommandedStock, ALongLegIsCutAlongAllOfItAndBadNumbersCutNothing) {
  Model model(tool(CutterKind::Ball, 1.0));
  model.stock.cut({10.0, 5.0, 1.0}, {20.0, 15.0, 1.0});  // the whole diagonal
  for (double t = 0.05; t < 1.0; t += 0.05) {
    DOUBLES_EQUAL(1.0, model.at(10.0 + 10.0 * t, 5.0 + 10.0 * t), 0.02);
  }
  const double removed = model.stock.removed_volume_mm3();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  model.stock.cut({15.0, 10.0, nan}, {15.0, 10.0, 0.0});
  DOUBLES_EQUAL(removed, model.stock.removed_volume_mm3(), 0.0);
}

TEST(CommandedStock, FarAwayOrHugeNumbersCutNothingAndAreNotCastOutOfRange) {
  Model model(tool(CutterKind::Ball, 3.0));
  model.stock.cut({5.0, 5.0, 1.0}, {1e300, 5.0, 1.0});  // a leg to almost infinity: bounded samples
  model.stock.cut({1e12, -1e12, 1.0}, {1e12, -1e12, 1.0});
  const double removed = model.stock.removed_volume_mm3();
  CHECK(removed < 20.0 * 3.0 * 6.0);  // at most what the part of the leg inside the block can cut
  LONGS_EQUAL(0, CommandedStock::cells_needed({{0, 0, 0}, {1e9, 1e9, 5}}, kCell));  // too many cells to be a block
}

TEST(CommandedStock, TooFewCellsOrAnEmptyBlockIsNotReady) {
  std::vector<float> few(10);
  const CommandedStock small(kBlock, kCell, tool(CutterKind::Ball, 3.0), few);
  CHECK_FALSE(small.ready());
  LONGS_EQUAL(0, CommandedStock::cells_needed({{0, 0, 0}, {0, 5, 5}}, kCell));
  LONGS_EQUAL(0, CommandedStock::cells_needed(kBlock, 0.0));
}
