// The whole generator: byte-identical output, reachability on the sample parts, refusals and warnings.
#include <cstring>
#include <string>

#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/sample_tables.hpp"
#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/sample_parts.hpp"
#include "toolchain/tablegen/table_generator.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::tablegen;

namespace {

bool same_bytes(const TableBytes& a, const TableBytes& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size()) == 0;
}

std::string error_of(const std::vector<Facet>& facets, const GeneratorOptions& options) {
  try {
    static_cast<void>(test::make_table(facets, options));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// Share of a part's points that are reachable, among those whose triangle normal is `up` or not.
struct Reach {
  std::size_t reachable = 0;
  std::size_t total = 0;
};

}  // namespace

TEST_GROUP(TableGenerator){};

TEST(TableGenerator, TheSameInputGivesTheSameBytesWhateverTheThreadCount) {
  GeneratorOptions options = test::default_job_options(1);
  options.extra_points = 500;
  const TableBytes one = test::make_table(test::default_part(), options);
  const TableBytes again = test::make_table(test::default_part(), options);
  options.threads = 2;
  const TableBytes two = test::make_table(test::default_part(), options);
  options.threads = 3;
  const TableBytes three = test::make_table(test::default_part(), options);
  CHECK(same_bytes(one, again));
  CHECK(same_bytes(one, two));
  CHECK(same_bytes(one, three));
  options.seed = 2;
  CHECK_FALSE(same_bytes(one, test::make_table(test::default_part(), options)));
}

TEST(TableGenerator, TheTableLoadsAndRecordsTheJob) {
  const TableBytes bytes = test::make_table(test::default_part(), test::default_job_options());
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  DOUBLES_EQUAL(3.0, part.header.tool_diameter_mm, 0.0);
  CHECK(part.header.covering_radius_mm <= part.header.requested_spacing_mm);
  CHECK(part.header.gouge_bound_mm <= kDefaultMaxGouge_mm);
  DOUBLES_EQUAL(17.0, part.header.part_min_mm[0], 1e-5);
  DOUBLES_EQUAL(6.0, part.header.part_max_mm[2], 1e-5);
  LONGS_EQUAL(24, part.header.source_triangle_count);
}

TEST(TableGenerator, FloorFacingFacesAreUnreachableAndTopsAreReachable) {
  const TableBytes bytes = test::make_table(test::default_part(), test::default_job_options());
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  Reach down;
  Reach top;
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    const bool reachable = (part.point_flags[i] & tables::kPointReachable) != 0;
    if (tables::point_normal(part, i).z_mm < -0.5f) {
      down.total += 1;
      down.reachable += reachable ? 1 : 0;
    } else if (tables::point_normal(part, i).z_mm > 0.5f) {
      top.total += 1;
      top.reachable += reachable ? 1 : 0;
    }
  }
  CHECK(down.total > 100 && top.total > 100);
  LONGS_EQUAL(0, down.reachable);
  LONGS_EQUAL(top.total, top.reachable);
  LONGS_EQUAL(18, part.header.reachable_triangle_count);  // all but the six bottom facets
}

TEST(TableGenerator, ASlotNarrowerThanTheToolHasAnUnreachableFloor) {
  // Slot 2 mm wide, floor at z = 3, between walls; the tool is a 3 mm ball.
  const TableBytes bytes = test::make_table(slotted_block(30.0, 12.0, 6.0, 2.0, 3.0, 10.0, 6.5), test::default_job_options());
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  Reach slot_floor;
  Reach block_top;
  for (std::uint32_t i = 0; i < part.point_count(); ++i) {
    const auto& p = part.points[i];
    const bool reachable = (part.point_flags[i] & tables::kPointReachable) != 0;
    const bool faces_up = tables::point_normal(part, i).z_mm > 0.5f;
    if (faces_up && std::abs(p.z_mm - 3.0f) < 1e-4f && p.y_mm > 11.5f && p.y_mm < 13.5f && p.x_mm > 11.0f && p.x_mm < 39.0f) {
      slot_floor.total += 1;
      slot_floor.reachable += reachable ? 1 : 0;
    }
    if (faces_up && std::abs(p.z_mm - 6.0f) < 1e-4f && (p.y_mm < 9.0f || p.y_mm > 16.0f) && p.x_mm > 12.0f && p.x_mm < 38.0f) {
      block_top.total += 1;
      block_top.reachable += reachable ? 1 : 0;
    }
  }
  CHECK(slot_floor.total > 100 && block_top.total > 100);
  LONGS_EQUAL(0, slot_floor.reachable);
  LONGS_EQUAL(block_top.total, block_top.reachable);
}

TEST(TableGenerator, RefusesASpacingWhoseGougeExceedsTheLimitUnlessForced) {
  GeneratorOptions options = test::default_job_options();
  options.spacing_mm = 0.5;  // a 3 mm ball dips 0.086 mm between such samples
  const std::string message = error_of(test::default_part(), options);
  CHECK_TEXT(message.find("--spacing 0.5 mm lets the tool dip up to 0.0857") != std::string::npos, message.c_str());
  CHECK(message.find("--max-gouge 0.004") != std::string::npos);
  options.force = true;
  CHECK(error_of(test::default_part(), options).empty());
}

TEST(TableGenerator, RefusesMorePointsThanTheControllerHolds) {
  GeneratorOptions options = test::default_job_options();
  options.tool.kind = geometry::CutterKind::Flat;  // a sharp corner: h = max gouge = 0.004 mm
  const std::string message = error_of(test::default_part(), options);
  CHECK_TEXT(message.find("test_part.stl: covering the surface to 0.004 mm needs") != std::string::npos, message.c_str());
  CHECK(message.find("more than the controller's capacity of 4194304") != std::string::npos);
}

TEST(TableGenerator, RefusesBadOptionsNamingThem) {
  GeneratorOptions options = test::default_job_options();
  options.max_gouge_mm = 0.0;
  CHECK(error_of(test::default_part(), options).find("--max-gouge 0: expected a finite number greater than 0") == 0);
  options = test::default_job_options();
  options.placement.scale = -1.0;
  CHECK(error_of(test::default_part(), options).find("--scale -1") == 0);
  options = test::default_job_options();
  options.allowance_mm = -0.1;
  CHECK(error_of(test::default_part(), options).find("--allowance -0.1") == 0);
  options = test::default_job_options();
  options.tool.corner_radius_mm = 5.0;
  options.tool.kind = geometry::CutterKind::BullNose;
  CHECK(error_of(test::default_part(), options).find("--tool/--holder: corner_radius_mm 5") == 0);
}

TEST(TableGenerator, WarnsAboutAnAllowanceBelowTheBacklashAndAnOpenMesh) {
  auto facets = test::default_part();
  facets.pop_back();  // a hole in the side
  const std::vector<std::byte> stl = encode_stl(facets, false, "holed");
  GeneratorReport report;
  static_cast<void>(generate_tables(stl, "holed.stl", test::default_job_options(), report, [](const char*, double) {}));
  bool backlash = false;
  bool open = false;
  for (const std::string& warning : report.warnings) {
    backlash = backlash || warning.find("smaller than the rig's largest backlash (0.125 mm)") != std::string::npos;
    open = open || warning.find("holed.stl: 3 open edges") != std::string::npos;
  }
  CHECK(backlash);
  CHECK(open);
  GeneratorOptions generous = test::default_job_options();
  generous.allowance_mm = 0.2;
  GeneratorReport quiet;
  static_cast<void>(generate_tables(encode_stl(test::default_part(), false, "hex"), "hex.stl", generous, quiet,
                                    [](const char*, double) {}));
  CHECK(quiet.warnings.empty());
}
