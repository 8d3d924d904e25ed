// What the journal's suites share (journal_fixtures.hpp).
#include "tests/support/journal_fixtures.hpp"

#include <cstdio>
#include <fstream>
#include <iterator>

#include <unistd.h>

#include "firmware/services/journal/cycle_codec.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

namespace stencil::testing {

using control::JournalRecord;
using control::SafeReason;
using namespace stencil::journal;

JournalRecord record_of(std::uint64_t cycle, SafeReason reason) {
  JournalRecord r{};
  r.cycle = cycle;
  r.time_ns = static_cast<std::int64_t>(cycle) * 1'000'000 + 17;
  r.device_mm[0] = 250.0 + 1e-3 * static_cast<double>(cycle);
  r.device_mm[1] = 125.123456789012345;
  r.device_mm[2] = -3.0;
  r.angles_rad[0] = 0.1;
  r.angles_rad[1] = -0.2;
  r.sample_counter = static_cast<std::uint32_t>(cycle * 3);
  r.fresh = cycle % 2 == 0;
  r.virtual_tip_mm[0] = 25.0;
  r.virtual_tip_mm[1] = 12.5 + 1e-9 * static_cast<double>(cycle);
  r.virtual_tip_mm[2] = 7.25;
  r.safe_reason = reason;
  r.touched_triangles = static_cast<std::uint32_t>(cycle / 7);
  r.force_n[0] = 0.25F;
  r.force_n[1] = -4.75F;
  r.force_n[2] = static_cast<float>(cycle) * 1e-3F;
  r.status_bits = 0x8001;
  r.read_status = cycle % 3 == 0 ? stencil::hal::ReadStatus::Rejected : stencil::hal::ReadStatus::Fresh;
  r.read_reason = cycle % 3 == 0 ? stencil::hal::HapticFault::SampleNotFinite : stencil::hal::HapticFault::None;
  r.max_force_n = 4.8 + 1e-3 * static_cast<double>(cycle / 50);
  r.max_offset_mm = 0.5;
  return r;
}

TempJournal::TempJournal() {
  char name[] = "/tmp/journal_tests_XXXXXX";
  const int fd = mkstemp(name);
  if (fd >= 0) {
    close(fd);
  }
  path = name;
}

TempJournal::~TempJournal() { std::remove(path.c_str()); }

std::vector<std::uint8_t> TempJournal::bytes() const {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

JournalStart start_of() {
  JournalStart start;
  start.tables_crc32 = 0xdeadbeef;
  start.triangle_count = 92;
  start.unix_time_ns = 1'796'000'000'000'000'000;
  start.program = "journal_tests";
  start.job = "pattern=raster seed=1";
  return start;
}

void write_job(const std::string& path, int cycles, int safe_from) {
  JournalWriter writer;
  CHECK_TRUE(writer.open(path, start_of()));
  for (int i = 0; i < cycles; ++i) {
    const SafeReason reason = safe_from >= 0 && i >= safe_from ? SafeReason::PoseJump : SafeReason::None;
    CHECK_TRUE(writer.append(record_of(static_cast<std::uint64_t>(i), reason)));
  }
  CHECK_TRUE(writer.close());
}

JournalVisitor Seen::visitor() {
  JournalVisitor v;
  v.start = [this](const JournalStart& s) {
    ++starts;
    start = s;
  };
  v.cycle = [this](const RecordedCycle& r) { cycles.push_back(r); };
  v.safe_state = [this](std::uint64_t cycle, SafeReason reason) { events.emplace_back(cycle, reason); };
  v.safe_source = [this](std::uint64_t, SafeReason, control::CommandSource source) { sources.push_back(source); };
  v.command = [this](const control::CommandEvent& e) { taken.push_back(e); };
  v.homed = [this](std::int64_t t) { homings.push_back(t); };
  v.machine_command = [this](const control::MachineCommandRecord& c) { commands.push_back(c); };
  v.resume = [this](const JournalResume& r) { resumes.push_back(r); };
  v.end = [this](std::uint64_t c, SafeReason reason) { endings.emplace_back(c, reason); };
  v.provenance = [this](const std::string& text) { provenances.push_back(text); };
  return v;
}

void check_same(const JournalRecord& a, const RecordedCycle& seen) {
  const JournalRecord& b = seen.record;
  LONGS_EQUAL(a.cycle, b.cycle);
  LONGS_EQUAL(a.time_ns, b.time_ns);
  LONGS_EQUAL(tip_check(a.virtual_tip_mm), seen.tip_check);
  for (int i = 0; i < 3; ++i) {
    CHECK(a.device_mm[i] == b.device_mm[i]);
    CHECK(!seen.tool_recorded || a.virtual_tip_mm[i] == b.virtual_tip_mm[i]);
    CHECK(!seen.tool_recorded || a.force_n[i] == b.force_n[i]);
  }
  CHECK(!seen.maxima_recorded || (a.max_force_n == b.max_force_n && a.max_offset_mm == b.max_offset_mm));
  CHECK(a.angles_rad[0] == b.angles_rad[0] && a.angles_rad[1] == b.angles_rad[1]);
  LONGS_EQUAL(a.sample_counter, b.sample_counter);
  CHECK(a.fresh == b.fresh);
  CHECK(a.safe_reason == b.safe_reason);
  LONGS_EQUAL(a.touched_triangles, b.touched_triangles);
  LONGS_EQUAL(a.status_bits, b.status_bits);
  CHECK(a.read_status == b.read_status && a.read_reason == b.read_reason);
}

std::vector<std::size_t> record_starts(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::size_t> starts;
  JournalVisitor offsets;
  offsets.offset = [&](std::size_t offset) { starts.push_back(offset); };
  const JournalReadResult read = read_journal(bytes.data(), bytes.size(), offsets);
  CHECK_TEXT(read.ok, read.error.c_str());
  starts.push_back(read.good_bytes);
  return starts;
}

control::MachineCommandRecord command_of(std::uint64_t update) {
  return {update, static_cast<std::int64_t>(update) * 33'333'333, {-1200, 35, static_cast<std::int32_t>(update)},
          {2, 0, 3}, {25.125, 12.0 + 1e-7 * static_cast<double>(update), 3.0}};
}

}  // namespace stencil::testing
