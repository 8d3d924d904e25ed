// The comparisons stencil-same-behaviour makes: two journals of the same job are the same apart from
// their start times and their Provenance records (which build, which command line), whichever side
// has them (version 3 against version 4); a real difference after a Provenance record is still found
// and placed. (The reports' comparison: report_comparison_tests.cpp.)
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "firmware/services/journal/journal_writer.hpp"
#include "toolchain/same_behaviour/journal_comparison.hpp"
#include "tests/support/old_journal.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct TempFile {
  std::string path;
  TempFile() {
    char name[] = "/tmp/same_behaviour_tests_XXXXXX";
    const int fd = mkstemp(name);
    if (fd >= 0) {
      close(fd);
    }
    path = name;
  }
  ~TempFile() { std::remove(path.c_str()); }
};

control::JournalRecord cycle_record(std::uint64_t cycle, double tip_x) {
  control::JournalRecord r{};
  r.cycle = cycle;
  r.time_ns = static_cast<std::int64_t>(cycle) * 1'000'000;
  r.virtual_tip_mm[0] = tip_x;
  r.fresh = true;
  return r;
}

// A job of 4 cycles; `provenance` "" writes none; `start_ns` the wall clock's start; cycle 2's tool at `x2`.
void write_job(const std::string& path, const std::string& provenance, std::int64_t start_ns, double x2 = 25.0) {
  journal::JournalWriter writer;
  journal::JournalStart start;
  start.tables_crc32 = 0x1234;
  start.triangle_count = 24;
  start.unix_time_ns = start_ns;
  start.program = "same_behaviour_tests";
  start.job = "pattern=raster";
  start.provenance = provenance;
  CHECK_TRUE(writer.open(path, start));
  for (std::uint64_t c = 0; c < 4; ++c) {
    CHECK_TRUE(writer.append(cycle_record(c, c == 2 ? x2 : 25.0)));
  }
  CHECK_TRUE(writer.append_end(4, control::SafeReason::None));
  CHECK_TRUE(writer.close());
}

// The same job as version 3 (no Provenance record) or 4 wrote it: a Cycle record per cycle.
void write_old_job(const std::string& path, std::uint32_t version, const std::string& provenance, std::int64_t start_ns,
                   double x2 = 25.0) {
  testing::OldJournal old(version, start_ns, provenance, "same_behaviour_tests", "pattern=raster");
  for (std::uint64_t c = 0; c < 4; ++c) {
    old.cycle(cycle_record(c, c == 2 ? x2 : 25.0));
  }
  old.end(4);
  old.write(path);
}

}  // namespace

TEST_GROUP(JournalComparison){};

TEST(JournalComparison, JournalsOfTheSameJobAreTheSameWhateverBuildAndStartWroteThem) {
  TempFile older, newer;
  write_job(older.path, "stencil-sim abc123 (GNU 12); command: /old/build/bin/stencil-sim --fast", 1'000);
  write_job(newer.path, "stencil-sim def456-dirty (GNU 12); command: /new/build/bin/stencil-sim --fast --report r.json", 2'000);
  const same_behaviour::JournalComparison result = same_behaviour::compare_journals(older.path, newer.path);
  STRCMP_EQUAL("", result.error.c_str());
  CHECK_EQUAL(0U, result.differences.size());
  CHECK_EQUAL(1U, result.start_times);
  CHECK_EQUAL(2U, result.provenance);
  CHECK_EQUAL(3U, result.records);  // start, one Cycles record of 4 cycles, end: the provenance left out
}

TEST(JournalComparison, ADifferentToolInACompactJournalIsFoundInItsCyclesRecord) {
  TempFile older, newer;
  write_job(older.path, "a", 1'000);
  write_job(newer.path, "b", 2'000, 25.001);
  const same_behaviour::JournalComparison result = same_behaviour::compare_journals(older.path, newer.path);
  STRCMP_EQUAL("", result.error.c_str());
  CHECK_EQUAL(1U, result.differences.size());
  STRCMP_CONTAINS("record 1 (cycles)", result.differences[0].c_str());  // start, then the cycles
  STRCMP_CONTAINS("its payload from byte", result.differences[0].c_str());
}

TEST(JournalComparison, AVersion3JournalWithoutProvenanceIsTheSameJobAsAVersion4One) {
  TempFile older, newer;
  write_old_job(older.path, 3, "", 1'000);
  write_old_job(newer.path, 4, "stencil-sim def456 (GNU 12); command: stencil-sim --fast", 2'000);
  const same_behaviour::JournalComparison result = same_behaviour::compare_journals(older.path, newer.path);
  STRCMP_EQUAL("", result.error.c_str());
  CHECK_EQUAL(0U, result.differences.size());
  CHECK_EQUAL(1U, result.provenance);
}

TEST(JournalComparison, ADifferenceAfterAProvenanceRecordIsFoundAndPlaced) {
  TempFile older, newer;
  write_old_job(older.path, 3, "", 1'000);
  write_old_job(newer.path, 4, "stencil-sim def456 (GNU 12); command: stencil-sim --fast", 2'000, 25.001);
  const same_behaviour::JournalComparison result = same_behaviour::compare_journals(older.path, newer.path);
  STRCMP_EQUAL("", result.error.c_str());
  CHECK_EQUAL(1U, result.differences.size());
  STRCMP_CONTAINS("record 3 (cycle 2)", result.differences[0].c_str());  // start, cycles 0, 1, 2
  STRCMP_CONTAINS("its payload from byte", result.differences[0].c_str());
  // Another version step than 3 to 4 is a difference of its own (4 to 5 changed every cycle's bytes).
  write_old_job(older.path, 4, "x", 1'000);
  write_job(newer.path, "x", 2'000);
  const same_behaviour::JournalComparison versions = same_behaviour::compare_journals(older.path, newer.path);
  CHECK(versions.differences.size() >= 1U);
  STRCMP_CONTAINS("the file versions differ: 4 and 5", versions.differences[0].c_str());
}
