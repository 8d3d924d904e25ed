// The state feed: what the controller writes is what a display reads, never writable by a display,
// and a region that is not a feed (or another build's) is refused. (Its cells' torn-read guard is
// seqlock_tests.cpp's.)
#include <sys/mman.h>

#include <cstring>
#include <vector>

#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/display_link/state_feed.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil;
using namespace stencil::display_link;

namespace {

struct Prism {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  Prism() { CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok); }
};

FeedFacts facts() {
  FeedFacts f;
  f.limits.board_force_limit_n = 4.0;
  f.reset_rule.still_time_s = 0.3;
  f.program = "stencil-test";
  return f;
}

}  // namespace

TEST_GROUP(StateFeed) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(StateFeed, WhatTheControllerWritesADisplayReads) {
  Prism prism;
  FeedWriter writer;
  std::string error;
  CHECK_TRUE_TEXT(writer.create(prism.part, facts(), error), error.c_str());
  FeedView view;
  CHECK_TRUE_TEXT(view.open(dup(writer.fd()), error), error.c_str());
  CHECK_EQUAL(prism.part.triangle_count(), view.header().triangle_count);
  STRCMP_EQUAL("stencil-test", view.header().program);
  DOUBLES_EQUAL(4.0, view.header().limits.board_force_limit_n, 0.0);
  DOUBLES_EQUAL(prism.part.triangles[3].vertices[1].y_mm, view.vertices(3)[4], 0.0);
  CHECK_EQUAL(prism.part.triangle_flags[5], view.flags(5));

  Figures figures{};
  figures.cycle = 77;
  figures.touched_count = 3;
  figures.telemetry.device_to_tool_mm = 1.5;
  writer.publish(figures);
  writer.mark_touched(2);
  writer.mark_touched(9);
  writer.mark_touched(prism.part.triangle_count() + 5);  // beyond the part: ignored
  for (std::uint64_t cycle = 1; cycle <= 3000; ++cycle) {
    writer.record_force(cycle, cycle == 2500 ? 4.5F : 1.0F);
  }
  Figures read{};
  CHECK(view.read(read));
  CHECK_EQUAL(77U, read.cycle);
  DOUBLES_EQUAL(1.5, read.telemetry.device_to_tool_mm, 0.0);
  std::vector<std::uint8_t> bits;
  view.touched(bits);
  CHECK_EQUAL((prism.part.triangle_count() + 7) / 8, bits.size());
  CHECK_EQUAL(0x04, bits[0]);
  CHECK_EQUAL(0x02, bits[1]);
  DOUBLES_EQUAL(4.5, view.force_peak(2000, 3000), 0.0);
  DOUBLES_EQUAL(1.0, view.force_peak(2500, 3000), 0.0);  // after the peak
  DOUBLES_EQUAL(1.0, view.force_peak(0, 2000), 0.0);     // before it (and older than the ring: what is left)
}

TEST(StateFeed, ADisplayCannotWriteOrGrowIt) {
  Prism prism;
  FeedWriter writer;
  std::string error;
  CHECK(writer.create(prism.part, facts(), error));
  void* writable = mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, writer.fd(), 0);
  CHECK(writable == MAP_FAILED);  // F_SEAL_FUTURE_WRITE
  CHECK(ftruncate(writer.fd(), 1 << 20) != 0);  // F_SEAL_GROW
}

TEST(StateFeed, ARegionThatIsNotThisBuildsFeedIsRefusedWithTheReason) {
  Prism prism;
  FeedWriter writer;
  std::string error;
  CHECK(writer.create(prism.part, facts(), error));
  const FeedLayout layout = feed_layout(prism.part.triangle_count());
  std::vector<unsigned char> copy(layout.total_bytes);
  std::memcpy(copy.data(), &writer.header(), sizeof(FeedHeader));
  FeedView view;
  CHECK(view.open_memory(copy.data(), copy.size(), error));
  auto* header = reinterpret_cast<FeedHeader*>(copy.data());
  header->version = static_cast<std::uint16_t>(kProtocolVersion + 1);
  CHECK_FALSE(view.open_memory(copy.data(), copy.size(), error));
  STRCMP_CONTAINS(("protocol version " + std::to_string(kProtocolVersion + 1) + ", this display speaks version " + std::to_string(kProtocolVersion)).c_str(), error.c_str());
  header->version = kProtocolVersion;
  header->figures_bytes += 8;
  CHECK_FALSE(view.open_memory(copy.data(), copy.size(), error));
  STRCMP_CONTAINS("another layout", error.c_str());
  header->figures_bytes -= 8;
  header->triangle_count += 1000;  // its regions would run past the end
  CHECK_FALSE(view.open_memory(copy.data(), copy.size(), error));
  STRCMP_CONTAINS("do not match its triangle count", error.c_str());
  header->triangle_count -= 1000;
  header->magic = 0;
  CHECK_FALSE(view.open_memory(copy.data(), copy.size(), error));
  STRCMP_CONTAINS("bad magic", error.c_str());
  CHECK_FALSE(view.open_memory(copy.data(), 16, error));
  STRCMP_CONTAINS("too small", error.c_str());
}
