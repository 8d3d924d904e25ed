// The loader against corrupted tables: every damage is refused with the field it is in, never adopted.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/core/tables/tool_section.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::tables;

namespace {

tablegen::TableBytes copy_of(const tablegen::TableBytes& source, std::size_t size) {
  tablegen::TableBytes copy(size);
  std::memcpy(copy.data(), source.data(), std::min(size, source.size()));
  return copy;
}

TableHeader header_of(const tablegen::TableBytes& bytes) {
  TableHeader header;
  std::memcpy(&header, bytes.data(), sizeof(header));
  return header;
}

void put_header(tablegen::TableBytes& bytes, const TableHeader& header) {
  std::memcpy(bytes.data(), &header, sizeof(header));
}

// Re-computes the CRC so that a deliberate change reaches the deeper checks.
void reseal(tablegen::TableBytes& bytes) {
  TableHeader header = header_of(bytes);
  header.crc32 = table_crc32({bytes.data(), bytes.size()});
  put_header(bytes, header);
}

template <typename T>
T* section(tablegen::TableBytes& bytes, TableSection which) {
  return reinterpret_cast<T*>(bytes.data() + header_of(bytes).sections[static_cast<std::size_t>(which)].offset);
}

TableLoadResult load(const tablegen::TableBytes& bytes, PartTables& tables) {
  return load_tables({bytes.data(), bytes.size()}, tables);
}

// Asserts the table is refused, naming `field`, and that nothing was adopted.
void check_refused(const tablegen::TableBytes& bytes, const char* field) {
  PartTables tables{};
  tables.header.point_count = 123;  // proves the loader clears what it was given
  const TableLoadResult result = load(bytes, tables);
  CHECK_FALSE(result.ok);
  STRCMP_EQUAL(field, result.field);
  CHECK(result.expected != nullptr && std::strlen(result.expected) > 0);
  LONGS_EQUAL(0, tables.point_count());
  CHECK(tables.points == nullptr);
}

}  // namespace

// Each test makes its own valid table (a few milliseconds), so nothing outlives a test and the
// leak detector stays meaningful.
TEST_GROUP(TableLoader) {
  tablegen::TableBytes table = test::make_table(test::default_part(), test::default_job_options());
  const tablegen::TableBytes& valid_table() const { return table; }

  // A copy of the valid table with its header changed and the CRC re-sealed must be refused for `field`.
  template <typename Change>
  void with_header(Change change, const char* field) const {
    tablegen::TableBytes bytes = copy_of(table, table.size());
    TableHeader header = header_of(bytes);
    change(header);
    put_header(bytes, header);
    reseal(bytes);
    check_refused(bytes, field);
  }
};

TEST(TableLoader, AdoptsWhatTheGeneratorWrites) {
  PartTables tables{};
  const TableLoadResult result = load(valid_table(), tables);
  CHECK_TRUE(result.ok);
  CHECK(tables.point_count() > 1000);
  LONGS_EQUAL(24, tables.triangle_count());
  CHECK(tables.node_count() > 1);
  CHECK(reinterpret_cast<const std::byte*>(tables.points) > valid_table().data());
  // The tool is the one the header names, and it classifies like a freshly built one.
  geometry::ToolBsp expected{};
  CHECK(geometry::build_tool_bsp(tables::tool_spec_of(tables.header), expected).ok);
  LONGS_EQUAL(expected.node_count, tables.tool.node_count);
  DOUBLES_EQUAL(1.5, tables.tool.envelope.cutter_radius_mm, 0.0);
  const auto inside = geometry::classify_in_tool_frame(tables.tool, {0.0, 0.0, 0.5});
  CHECK(inside.contact == geometry::PointContact::Penetrating);
}

TEST(TableLoader, RefusesEveryTruncation) {
  const std::size_t size = valid_table().size();
  for (std::size_t length = 0; length < size; length += (length < 600 ? 1 : 997)) {
    PartTables tables{};
    CHECK_FALSE(load(copy_of(valid_table(), length), tables).ok);
  }
  check_refused(copy_of(valid_table(), 100), "header");
  check_refused(copy_of(valid_table(), size - 1), "header.file_bytes");
}

TEST(TableLoader, RefusesExtraBytes) { check_refused(copy_of(valid_table(), valid_table().size() + 64), "header.file_bytes"); }

TEST(TableLoader, RefusesAnyFlippedByteThroughTheChecksum) {
  std::mt19937_64 random(31);
  const std::size_t size = valid_table().size();
  for (int trial = 0; trial < 300; ++trial) {
    tablegen::TableBytes bytes = copy_of(valid_table(), size);
    const std::size_t at = kCrcStartOffset + random() % (size - kCrcStartOffset);
    bytes.data()[at] ^= std::byte{static_cast<unsigned char>(1u + random() % 255u)};
    PartTables tables{};
    const TableLoadResult result = load(bytes, tables);
    CHECK_FALSE(result.ok);
  }
  tablegen::TableBytes bytes = copy_of(valid_table(), size);
  bytes.data()[size / 2] ^= std::byte{0x10};
  check_refused(bytes, "header.crc32");
}

TEST(TableLoader, RefusesTheWrongMagicVersionOrHeaderSize) {
  tablegen::TableBytes bytes = copy_of(valid_table(), valid_table().size());
  bytes.data()[0] = std::byte{'X'};
  check_refused(bytes, "header.magic");

  bytes = copy_of(valid_table(), valid_table().size());
  TableHeader header = header_of(bytes);
  header.format_version = kTableFormatVersion + 1;
  put_header(bytes, header);
  reseal(bytes);
  check_refused(bytes, "header.format_version");

  // A table of the format before the packed leaves: refused as older, which the programs word as
  // "format version 1: regenerate with stencil-tablegen".
  bytes = copy_of(valid_table(), valid_table().size());
  header = header_of(bytes);
  header.format_version = 1;
  put_header(bytes, header);
  reseal(bytes);
  PartTables tables{};
  const TableLoadResult older = load(bytes, tables);
  CHECK_FALSE(older.ok);
  STRCMP_EQUAL("header.format_version", older.field);
  CHECK(older.expected == kOlderVersion);
  DOUBLES_EQUAL(1.0, older.value, 0.0);
  // And one without the groups' moments, the format before this one.
  header.format_version = kTableFormatVersion - 1;
  put_header(bytes, header);
  reseal(bytes);
  const TableLoadResult previous = load(bytes, tables);
  CHECK_FALSE(previous.ok);
  CHECK(previous.expected == kOlderVersion);
  DOUBLES_EQUAL(4.0, previous.value, 0.0);

  bytes = copy_of(valid_table(), valid_table().size());
  header = header_of(bytes);
  header.header_bytes = 256;
  put_header(bytes, header);
  reseal(bytes);
  check_refused(bytes, "header.header_bytes");
}

TEST(TableLoader, RefusesCountsBeyondCapacityOrDisagreeingWithSections) {
  with_header([](TableHeader& h) { h.point_count = kMaxTablePoints + 1; }, "header.point_count");
  with_header([](TableHeader& h) { h.point_count = 0; }, "header.point_count");
  with_header([](TableHeader& h) { h.triangle_count = kMaxTableTriangles + 1; }, "header.triangle_count");
  with_header([](TableHeader& h) { h.node_count = 0; }, "header.node_count");
  with_header([](TableHeader& h) { h.point_count -= 1; }, "sections.points");
  with_header([](TableHeader& h) { h.triangle_count += 1; }, "sections.triangles");
  with_header([](TableHeader& h) { h.sections[1].offset += 8; }, "sections.points");
  with_header([](TableHeader& h) { h.sections[2].offset = h.sections[1].offset; }, "sections.leaves");
  with_header([](TableHeader& h) { h.leaf_count = 0; }, "header.leaf_count");
  with_header([](TableHeader& h) { h.leaf_count = h.node_count + 1; }, "header.leaf_count");
  with_header([](TableHeader& h) { h.leaf_count -= 1; }, "sections.leaves");
  with_header([](TableHeader& h) { h.sections[7].bytes = ~0ull; }, "sections.nodes");
  with_header([](TableHeader& h) { h.flags = 1; }, "header.flags");
  with_header([](TableHeader& h) { h.vertex_point_count = h.point_count + 1; }, "header.vertex_point_count");
  with_header([](TableHeader& h) { h.gouge_bound_mm = std::numeric_limits<double>::quiet_NaN(); },
              "header.gouge_bound_mm");
  with_header([](TableHeader& h) { h.workspace_mm[1] = 0.0; }, "header.workspace_mm");
}

TEST(TableLoader, RefusesABadToolSpecOrATreeThatIsNotTheSpecs) {
  with_header([](TableHeader& h) { h.tool_kind = 7; }, "header.tool_kind");
  with_header([](TableHeader& h) { h.tool_kind = 256; }, "header.tool_kind");  // would wrap to flat as a byte
  with_header([](TableHeader& h) { h.tool_diameter_mm = -3.0; }, "diameter_mm");
  with_header([](TableHeader& h) { h.tool_diameter_mm = 2.0; }, "tool");  // a valid spec, but not this tree

  tablegen::TableBytes bytes = copy_of(valid_table(), valid_table().size());
  section<ToolSection>(bytes, TableSection::Tool)->surfaces[1].radius_mm = 1.4;  // a thinner flute side
  reseal(bytes);
  check_refused(bytes, "tool");
}

TEST(TableLoader, RefusesBadNumbersInThePointsAndTriangles) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  tablegen::TableBytes bytes = copy_of(valid_table(), valid_table().size());
  section<PackedPoint>(bytes, TableSection::Points)[17].y_mm = static_cast<float>(nan);
  reseal(bytes);
  check_refused(bytes, "points");

  bytes = copy_of(valid_table(), valid_table().size());
  section<LeafBlock>(bytes, TableSection::Leaves)[1].nx[5] = 2.0f;
  reseal(bytes);
  check_refused(bytes, "leaves.normals");

  bytes = copy_of(valid_table(), valid_table().size());
  section<LeafBlock>(bytes, TableSection::Leaves)[0].nz[5] = std::numeric_limits<float>::infinity();
  reseal(bytes);
  check_refused(bytes, "leaves.normals");

  bytes = copy_of(valid_table(), valid_table().size());
  section<std::uint32_t>(bytes, TableSection::TriangleIds)[3] = 24;
  reseal(bytes);
  PartTables tables{};
  const TableLoadResult result = load(bytes, tables);
  STRCMP_EQUAL("triangle_ids", result.field);
  LONGS_EQUAL(3, result.index);
  DOUBLES_EQUAL(24.0, result.value, 0.0);

  bytes = copy_of(valid_table(), valid_table().size());
  section<std::uint8_t>(bytes, TableSection::PointFlags)[0] = 0x80;
  reseal(bytes);
  check_refused(bytes, "point_flags");

  bytes = copy_of(valid_table(), valid_table().size());
  section<PackedTriangle>(bytes, TableSection::Triangles)[2].vertices[1].z_mm = static_cast<float>(nan);
  reseal(bytes);
  check_refused(bytes, "triangles");

  bytes = copy_of(valid_table(), valid_table().size());
  section<std::uint8_t>(bytes, TableSection::TriangleFlags)[1] = 0x02;
  reseal(bytes);
  check_refused(bytes, "triangle_flags");
}

TEST(TableLoader, RefusesAMalformedTree) {
  const auto with_nodes = [this](auto change, const char* field) {
    tablegen::TableBytes bytes = copy_of(valid_table(), valid_table().size());
    BvhNode* nodes = section<BvhNode>(bytes, TableSection::Nodes);
    change(nodes, header_of(bytes).node_count);
    reseal(bytes);
    check_refused(bytes, field);
  };
  const auto first_leaf = [](const BvhNode* nodes, std::uint32_t count) {
    for (std::uint32_t i = 0; i < count; ++i) {
      if (nodes[i].point_count > 0) {
        return i;
      }
    }
    return count;
  };
  with_nodes([](BvhNode* n, std::uint32_t count) { n[0].right_child = count; }, "nodes.right_child");
  with_nodes([](BvhNode* n, std::uint32_t) { n[0].right_child = 1; }, "nodes.right_child");
  with_nodes([&](BvhNode* n, std::uint32_t count) { n[first_leaf(n, count)].first_point += 1; }, "nodes.leaf");
  with_nodes([&](BvhNode* n, std::uint32_t count) { n[first_leaf(n, count)].point_count = kMaxLeafPoints + 1; },
             "nodes.leaf");
  with_nodes([&](BvhNode* n, std::uint32_t count) { n[first_leaf(n, count)].dop_max[0] -= 0.5; }, "nodes.dop");
  with_nodes([](BvhNode* n, std::uint32_t) { n[1].dop_max[2] = n[0].dop_max[2] + 1.0; }, "nodes.dop");
  with_nodes([](BvhNode* n, std::uint32_t) { n[0].dop_min[3] = std::numeric_limits<double>::quiet_NaN(); },
             "nodes.dop");
  with_nodes([](BvhNode* n, std::uint32_t) { n[0].dop_min[4] = n[0].dop_max[4] + 1.0; }, "nodes.dop");
  // The root's right subtree made to skip a node: the walk no longer meets the nodes in order.
  with_nodes([](BvhNode* n, std::uint32_t) { n[0].right_child += 1; }, "nodes");
}

TEST(TableLoader, RefusesLeafBlocksThatAreNotTheirLeaves) {
  const auto with_leaves = [this](auto change, const char* field) {
    tablegen::TableBytes bytes = copy_of(valid_table(), valid_table().size());
    change(section<LeafBlock>(bytes, TableSection::Leaves), section<BvhNode>(bytes, TableSection::Nodes),
           header_of(bytes));
    reseal(bytes);
    check_refused(bytes, field);
  };
  // A point of a block that is not the points section's: a verdict from the lanes would not be the point's.
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) { b[2].y_mm[3] += 0.001F; }, "leaves.points");
  // A padding lane that is not the last point again.
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader& h) {
    for (std::uint32_t leaf = 0; leaf < h.leaf_count; ++leaf) {
      if (b[leaf].point_count < kMaxLeafPoints) {
        b[leaf].x_mm[kMaxLeafPoints - 1] += 1.0F;
        return;
      }
    }
    b[0].x_mm[0] += 1.0F;  // every leaf full: any change is refused alike
  }, "leaves.points");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) { b[0].first_point += 1; }, "leaves");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) { b[1].radius_mm *= 0.5F; }, "leaves.sphere");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) { b[1].centre_mm[2] += 1.0F; }, "leaves.sphere");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) { b[1].radius_mm = -1.0F; }, "leaves.sphere");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) { b[0].reserved[7] = 1; }, "leaves.reserved");
  // The moments the query settles a whole leaf from: one float's last bit off is refused.
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) {
    b[1].centroid_mm[1] = std::nextafter(b[1].centroid_mm[1], 1e9F);
  }, "leaves.centroid");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) {
    b[2].mean_normal[2] = std::nextafter(b[2].mean_normal[2], -1e9F);
  }, "leaves.mean_normal");
  // Each group's moments likewise, and a group past the leaf's points must be zero.
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) {
    b[1].group_centroid_mm[0][2] = std::nextafter(b[1].group_centroid_mm[0][2], 1e9F);
  }, "leaves.group_centroid");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) {
    b[0].group_mean_normal[1][1] = std::nextafter(b[0].group_mean_normal[1][1], -1e9F);
  }, "leaves.group_mean_normal");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader&) {
    b[2].group_radius_mm[0] = std::nextafter(b[2].group_radius_mm[0], 0.0F);  // one point outside it
  }, "leaves.group_radius");
  with_leaves([](LeafBlock* b, BvhNode*, const TableHeader& h) {
    for (std::uint32_t leaf = 0; leaf < h.leaf_count; ++leaf) {
      if (b[leaf].point_count <= (kLeafGroups - 1) * kLeafGroupPoints) {
        b[leaf].group_radius_mm[kLeafGroups - 1] = 1.0F;
        return;
      }
    }
    b[0].group_radius_mm[0] += 1.0F;  // every leaf full: any change is refused alike
  }, "leaves.group_radius");
  // Nodes numbering their blocks out of order, or an internal node naming one.
  with_leaves([](LeafBlock*, BvhNode* n, const TableHeader& h) {
    for (std::uint32_t i = 0; i < h.node_count; ++i) {
      if (n[i].point_count > 0) {
        n[i].leaf += 1;
        return;
      }
    }
  }, "nodes.leaf_block");
  with_leaves([](LeafBlock*, BvhNode* n, const TableHeader&) { n[0].leaf = 1; }, "nodes.leaf_block");
}

TEST(TableLoader, RefusesAMisalignedBuffer) {
  tablegen::TableBytes shifted(table.size() + 8);
  std::memcpy(shifted.data() + 4, table.data(), table.size());
  PartTables tables{};
  const TableLoadResult result = load_tables({shifted.data() + 4, table.size()}, tables);
  CHECK_FALSE(result.ok);
  STRCMP_EQUAL("bytes", result.field);
}

TEST(TableLoader, SurvivesRandomDamageBehindAValidChecksum) {
  // Whatever the damage, the loader answers (under ASan in CI: without reading out of bounds).
  std::mt19937_64 random(32);
  const std::size_t size = valid_table().size();
  int refused = 0;
  for (int trial = 0; trial < 300; ++trial) {
    tablegen::TableBytes bytes = copy_of(valid_table(), size);
    const int changes = 1 + static_cast<int>(random() % 8);
    for (int c = 0; c < changes; ++c) {
      const std::size_t at = kCrcStartOffset + 4 + random() % (size - kCrcStartOffset - 4);
      bytes.data()[at] = std::byte{static_cast<unsigned char>(random())};
    }
    reseal(bytes);
    PartTables tables{};
    refused += load(bytes, tables).ok ? 0 : 1;
  }
  CHECK(refused > 100);  // most random damage lands in checked numbers; padding bytes may not matter
}
