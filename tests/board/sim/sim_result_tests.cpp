// What a simulated job reports of itself that a unit can check (board/sim/sim_result): the fraction
// of the part's reachable triangles touched (unreachable ones never count, a part with none reachable
// is covered), and this process's resident memory. fill_result gathers a whole run's figures: the
// e2e cases (sim_raster_corner, sim_same_report_twice) hold it to what a run measured.
#include <cstdint>
#include <memory>

#include "board/sim/sim_result.hpp"
#include "firmware/core/stencil/triangle_set.hpp"
#include "firmware/core/tables/table_format.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

TEST_GROUP(SimResult){};

TEST(SimResult, CoverageCountsOnlyReachableTrianglesTouched) {
  const test::LoadedPart loaded(test::default_part(), 1);
  CHECK_TRUE(loaded.loaded);
  const tables::PartTables& part = loaded.part;
  const std::uint32_t reachable = part.header.reachable_triangle_count;
  CHECK(reachable > 1U && reachable < part.triangle_count());  // the prism's floor faces down
  auto touched = std::make_unique<engine::TriangleSet>();
  DOUBLES_EQUAL(0.0, reachable_coverage(part, *touched), 0.0);
  std::uint32_t first_reachable = 0, first_unreachable = 0;
  bool found_reachable = false, found_unreachable = false;
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    const bool is_reachable = (part.triangle_flags[t] & tables::kTriangleReachable) != 0;
    if (is_reachable && !found_reachable) {
      first_reachable = t;
      found_reachable = true;
    } else if (!is_reachable && !found_unreachable) {
      first_unreachable = t;
      found_unreachable = true;
    }
  }
  static_cast<void>(touched->insert(first_unreachable));
  DOUBLES_EQUAL(0.0, reachable_coverage(part, *touched), 0.0);
  static_cast<void>(touched->insert(first_reachable));
  DOUBLES_EQUAL(1.0 / reachable, reachable_coverage(part, *touched), 1e-12);
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    static_cast<void>(touched->insert(t));
  }
  DOUBLES_EQUAL(1.0, reachable_coverage(part, *touched), 1e-12);
}

TEST(SimResult, APartWithNothingReachableIsCovered) {
  const test::LoadedPart loaded(test::default_part(), 1);
  tables::PartTables part = loaded.part;
  part.header.reachable_triangle_count = 0;
  const auto touched = std::make_unique<engine::TriangleSet>();
  DOUBLES_EQUAL(1.0, reachable_coverage(part, *touched), 0.0);
}

TEST(SimResult, ResidentMemoryGrowsWithWhatIsTouched) {
  const std::int64_t before = resident_kb();
  CHECK(before > 0);
  // 16 MiB written page by page must show in the resident set.
  const std::size_t bytes = std::size_t{16} << 20;
  auto block = std::make_unique<unsigned char[]>(bytes);
  for (std::size_t i = 0; i < bytes; i += 4096) {
    block[i] = static_cast<unsigned char>(i);
  }
  CHECK(resident_kb() >= before + 8 * 1024);
  CHECK(block[4096] == 0);
}
