// The ground truth of a cut: the gouge of a swept cutter against the part's own triangles, and each
// cell's signed distance to the part (the Z-map itself: stock_zmap_tests.cpp).
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
