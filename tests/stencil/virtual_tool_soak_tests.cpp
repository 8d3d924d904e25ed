// A thousand device trajectories per sample part, random and adversarial, against the exact oracle:
// the ball end mill never cuts the true part deeper than the table's undetectable-gouge bound.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/sample_tables.hpp"
#include "tests/support/gouge_oracle.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::engine;

namespace {


// Kinds of trajectory, each a short burst of device samples.
std::vector<Eigen::Vector3d> trajectory(std::mt19937_64& random, int kind, const Eigen::Vector3d& target) {
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> path;
  const Eigen::Vector3d start(50.0 * unit(random), 25.0 * unit(random), 4.0 + 8.0 * unit(random));
  switch (kind % 4) {
    case 0:  // a random walk with steps from fine to coarse
      path.push_back(start);
      for (int i = 0; i < 40; ++i) {
        path.push_back(path.back() + (0.05 + 1.0 * unit(random)) * Eigen::Vector3d(gaussian(random), gaussian(random), gaussian(random)));
      }
      break;
    case 1:  // a plunge at the target, then parked deep inside
      for (int i = 0; i <= 20; ++i) path.push_back(start + (target - Eigen::Vector3d(0, 0, 2.0) - start) * (i / 20.0));
      for (int i = 0; i < 10; ++i) path.push_back(target - Eigen::Vector3d(0, 0, 2.0));
      break;
    case 2:  // zig-zags into the target (a concave corner): alternate sides, each cycle deeper
      for (int i = 0; i < 40; ++i) {
        const double side = (i % 2 == 0 ? 1.0 : -1.0) * (2.0 - 0.05 * i);
        path.push_back(target + Eigen::Vector3d(side, 0.3 * side, 1.5 - 0.08 * i));
      }
      break;
    default:  // fast straight sweeps across the part, each cycle a big jump
      for (int i = 0; i <= 25; ++i) path.push_back(Eigen::Vector3d(2.0 + 1.84 * i, target.y(), target.z() - 0.5));
      break;
  }
  return path;
}

void soak(const std::vector<tablegen::Facet>& facets, const Eigen::Vector3d& corner, std::uint64_t seed) {
  const tablegen::TableBytes bytes = test::make_table(facets, test::default_job_options(2));
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  std::mt19937_64 random(seed);
  const ContactParameters parameters{};
  double worst = 0.0;
  int cycles = 0;
  for (int t = 0; t < 1000; ++t) {
    VirtualTool tool(part, {25.0, 12.5, 20.0});
    for (const Eigen::Vector3d& desired : trajectory(random, t, corner)) {
      const RemediationResult result = tool.step(desired, parameters);
      ++cycles;
      if (result.status == RemediationStatus::Fault || check_legal(part, tool.pose()) != Legality::Legal) {
        FAIL("the virtual tool faulted or ended illegal");
      }
      worst = std::max(worst, test::ball_end_gouge_mm(part, tool.tip_mm()));
    }
  }
  CHECK(cycles > 20000);
  if (worst > part.header.gouge_bound_mm + 1e-5) {
    FAIL("the virtual tool gouged the true surface beyond the table's bound");
  }
}

}  // namespace

TEST_GROUP(VirtualToolSoak){};

TEST(VirtualToolSoak, HexagonalPrismWithTheFloorCornerAsTarget) {
  // The prism's -x corner meets the stock floor: a concave corner between the part and the floor plane.
  soak(tablegen::hexagonal_prism(8.0, 6.0, 25.0, 12.5), {17.0 - 1.5, 12.5, 0.0}, 81);
}

TEST(VirtualToolSoak, SlottedBlockWithTheSlotFloorCornerAsTarget) {
  soak(tablegen::slotted_block(30.0, 12.0, 6.0, 2.0, 3.0, 10.0, 6.5), {25.0, 11.5, 3.0}, 82);
}

TEST(VirtualToolSoak, ThinFinWithItsFootAsTarget) {
  soak(tablegen::thin_fin(20.0, 0.6, 8.0, 15.0, 12.2), {25.0, 12.2 - 1.5, 0.0}, 83);
}
