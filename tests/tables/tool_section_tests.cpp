// The tool tree's file form (tables/tool_section.hpp), on every sample tool: every field of the
// built tree lands in its place, every unused and reserved byte is zero whatever the memory held
// (so equal trees give equal bytes, and the tables' CRC with them), and the header's tool spec
// reads back as it was stored without touching the rest of the header.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/geometry/tool_bsp_builder.hpp"
#include "firmware/core/tables/tool_section.hpp"
#include "tests/support/sample_tools.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::tables;

namespace {

bool all_zero(const void* bytes, std::size_t size) {
  const auto* p = static_cast<const std::uint8_t*>(bytes);
  for (std::size_t i = 0; i < size; ++i) {
    if (p[i] != 0) {
      return false;
    }
  }
  return true;
}

}  // namespace

TEST_GROUP(ToolSection){};

TEST(ToolSection, EveryFieldOfTheTreeLandsInItsPlace) {
  for (const test::NamedTool& named : test::kSampleTools) {
    geometry::ToolBsp tool{};
    CHECK_TEXT(geometry::build_tool_bsp(named.spec, tool).ok, named.name);
    ToolSection section{};
    encode_tool_section(tool, section);
    LONGS_EQUAL(tool.surface_count, section.surface_count);
    LONGS_EQUAL(tool.node_count, section.node_count);
    LONGS_EQUAL(tool.region_count, section.region_count);
    for (std::size_t i = 0; i < tool.surface_count; ++i) {
      const geometry::ImplicitSurface& s = tool.surfaces[i];
      LONGS_EQUAL(static_cast<int>(s.kind), section.surfaces[i].kind);
      LONGS_EQUAL(static_cast<int>(s.solid_side), section.surfaces[i].solid_side);
      DOUBLES_EQUAL(s.center_r_mm, section.surfaces[i].center_r_mm, 0.0);
      DOUBLES_EQUAL(s.center_z_mm, section.surfaces[i].center_z_mm, 0.0);
      DOUBLES_EQUAL(s.radius_mm, section.surfaces[i].radius_mm, 0.0);
    }
    for (std::size_t i = 0; i < tool.node_count; ++i) {
      const geometry::BspNode& n = tool.nodes[i];
      const ToolSectionNode& e = section.nodes[i];
      LONGS_EQUAL(static_cast<int>(n.test), e.test);
      LONGS_EQUAL(n.surface_a, e.surface_a);
      LONGS_EQUAL(n.surface_b, e.surface_b);
      LONGS_EQUAL(static_cast<int>(n.when_true.kind), e.when_true_kind);
      LONGS_EQUAL(n.when_true.index, e.when_true_index);
      LONGS_EQUAL(static_cast<int>(n.when_false.kind), e.when_false_kind);
      LONGS_EQUAL(n.when_false.index, e.when_false_index);
    }
    for (std::size_t i = 0; i < tool.region_count; ++i) {
      LONGS_EQUAL(tool.regions[i].surface, section.regions[i].surface);
      LONGS_EQUAL(static_cast<int>(tool.regions[i].face), section.regions[i].face);
    }
  }
}

TEST(ToolSection, EveryUnusedAndReservedByteIsZeroWhateverTheMemoryHeld) {
  for (const test::NamedTool& named : test::kSampleTools) {
    geometry::ToolBsp tool;
    std::memset(&tool, 0x5A, sizeof(tool));  // the tree's own padding and unused entries: garbage
    CHECK_TEXT(geometry::build_tool_bsp(named.spec, tool).ok, named.name);
    ToolSection section;
    std::memset(&section, 0xA5, sizeof(section));
    encode_tool_section(tool, section);
    LONGS_EQUAL(0, section.reserved);
    for (std::size_t i = 0; i < geometry::kMaxToolSurfaces; ++i) {
      const ToolSectionSurface& s = section.surfaces[i];
      CHECK_TEXT(all_zero(s.reserved, sizeof(s.reserved)), named.name);
      if (i >= tool.surface_count) {
        CHECK_TEXT(all_zero(&s, sizeof(s)), named.name);
      }
    }
    for (std::size_t i = 0; i < geometry::kMaxToolNodes; ++i) {
      LONGS_EQUAL(0, section.nodes[i].reserved);
      if (i >= tool.node_count) {
        CHECK_TEXT(all_zero(&section.nodes[i], sizeof(ToolSectionNode)), named.name);
      }
    }
    for (std::size_t i = 0; i < geometry::kMaxToolRegions; ++i) {
      CHECK_TEXT(all_zero(section.regions[i].reserved, sizeof(section.regions[i].reserved)), named.name);
      if (i >= tool.region_count) {
        CHECK_TEXT(all_zero(&section.regions[i], sizeof(ToolSectionRegion)), named.name);
      }
    }
    // The same tree built on clean memory gives the same bytes.
    geometry::ToolBsp clean{};
    CHECK(geometry::build_tool_bsp(named.spec, clean).ok);
    ToolSection again{};
    encode_tool_section(clean, again);
    MEMCMP_EQUAL(&again, &section, sizeof(section));
  }
}

TEST(ToolSection, TheHeadersToolSpecReadsBackAsStoredAndTheRestOfTheHeaderIsUntouched) {
  for (const test::NamedTool& named : test::kSampleTools) {
    TableHeader header;
    std::memset(&header, 0x3C, sizeof(header));
    TableHeader before;
    std::memcpy(&before, &header, sizeof(header));
    store_tool_spec(named.spec, header);
    const geometry::ToolSpec back = tool_spec_of(header);
    CHECK_TEXT(back.kind == named.spec.kind, named.name);
    DOUBLES_EQUAL(named.spec.diameter_mm, back.diameter_mm, 0.0);
    DOUBLES_EQUAL(named.spec.flute_length_mm, back.flute_length_mm, 0.0);
    DOUBLES_EQUAL(named.spec.corner_radius_mm, back.corner_radius_mm, 0.0);
    DOUBLES_EQUAL(named.spec.holder_diameter_mm, back.holder_diameter_mm, 0.0);
    DOUBLES_EQUAL(named.spec.holder_length_mm, back.holder_length_mm, 0.0);
    // Everything before the tool's fields and after them is as it was.
    MEMCMP_EQUAL(&before, &header, offsetof(TableHeader, tool_kind));
    const std::size_t after = offsetof(TableHeader, tool_holder_length_mm) + sizeof(double);
    MEMCMP_EQUAL(reinterpret_cast<const std::uint8_t*>(&before) + after,
                 reinterpret_cast<const std::uint8_t*>(&header) + after, sizeof(header) - after);
  }
}
