// JournalWriter: what it writes reads back exactly (the tool whole where a replay needs it, one
// safe-state event however long the safe state lasts), what it puts on the disk at once and what on
// the clock, its failures (a full disk, a file it cannot create), a machine target counted as written
// only once it is in the file, and a job carried on in the same file (the torn tail cut off, old
// versions carried on or refused). Read back through the real reader, in a real file.
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/journal_fixtures.hpp"
#include "tests/support/old_journal.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::JournalRecord;
using stencil::control::SafeReason;
using stencil::testing::OldJournal;
using namespace stencil::journal;
using namespace stencil::testing;

TEST_GROUP(JournalWriter){};

TEST(JournalWriter, WhatIsWrittenReadsBackExactlyWithTheStartAndTheSafeStateEvent) {
  TempJournal file;
  write_job(file.path, 300, 250);
  Seen seen;
  const JournalReadResult read = read_journal_file(file.path, seen.visitor());
  CHECK_TRUE(read.ok);
  LONGS_EQUAL(0, read.tail_bytes);
  LONGS_EQUAL(1, seen.starts);
  LONGS_EQUAL(0xdeadbeef, seen.start.tables_crc32);
  LONGS_EQUAL(92, seen.start.triangle_count);
  CHECK(seen.start.unix_time_ns == start_of().unix_time_ns);
  STRCMP_EQUAL("journal_tests", seen.start.program.c_str());
  STRCMP_EQUAL("pattern=raster seed=1", seen.start.job.c_str());
  LONGS_EQUAL(300, seen.cycles.size());
  int tools = 0;
  for (int i = 0; i < 300; ++i) {
    const RecordedCycle& cycle = seen.cycles[static_cast<std::size_t>(i)];
    check_same(record_of(static_cast<std::uint64_t>(i), i >= 250 ? SafeReason::PoseJump : SafeReason::None), cycle);
    // The tool whole at the run's first cycle, wherever the touched set grew, and where the safe
    // state came: the resume rebuilds the touched set from these.
    const bool grew = i > 0 && i % 7 == 0;
    CHECK_EQUAL(i == 0 || grew || i == 250, cycle.tool_recorded);
    tools += cycle.tool_recorded ? 1 : 0;
    CHECK_TRUE(cycle.maxima_recorded);
  }
  LONGS_EQUAL(1 + 42 + 1, tools);  // the first, 42 growths (7 to 294), the safe state's (not a growth)
  LONGS_EQUAL(1, seen.events.size());  // one event, not one per cycle in the safe state
  LONGS_EQUAL(250, seen.events[0].first);
  CHECK(seen.events[0].second == SafeReason::PoseJump);
  // Start; cycles 0-99, 100-199, 200-250 (ended by the event); the event; cycles 251-299.
  LONGS_EQUAL(1 + 3 + 1 + 1, read.records);
}

TEST(JournalWriter, TheSafeStateEventIsOnTheDiskTheMomentItIsAppended) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  for (int i = 0; i < 10; ++i) {
    CHECK_TRUE(writer.append(record_of(static_cast<std::uint64_t>(i))));
  }
  const std::uint64_t syncs = writer.syncs();
  CHECK_TRUE(writer.append(record_of(10, SafeReason::DeviceStale)));
  LONGS_EQUAL(syncs + 1, writer.syncs());
  // Read while the writer is still open, as after a crash right here.
  Seen seen;
  const std::vector<std::uint8_t> bytes = file.bytes();
  const JournalReadResult read = read_journal(bytes.data(), bytes.size(), seen.visitor());
  CHECK_TRUE(read.ok);
  LONGS_EQUAL(11, seen.cycles.size());
  LONGS_EQUAL(1, seen.events.size());
  CHECK(seen.events[0].second == SafeReason::DeviceStale);
}

TEST(JournalWriter, SyncsWhenASecondHasPassedAndNotBefore) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  const std::uint64_t after_open = writer.syncs();
  CHECK_TRUE(writer.append(record_of(0)));
  CHECK_TRUE(writer.sync_if_due(5'000'000'000));  // the first look syncs
  LONGS_EQUAL(after_open + 1, writer.syncs());
  CHECK_TRUE(writer.sync_if_due(5'900'000'000));
  LONGS_EQUAL(after_open + 1, writer.syncs());
  CHECK_TRUE(writer.sync_if_due(6'000'000'000));
  LONGS_EQUAL(after_open + 2, writer.syncs());
}

TEST(JournalWriter, AFullDiskIsAFailureThatSaysSo) {
  JournalWriter writer;
  // /dev/full takes the open and refuses every write with ENOSPC.
  CHECK_FALSE(writer.open("/dev/full", start_of()));
  STRCMP_CONTAINS("/dev/full: write failed: No space left on device", writer.error().c_str());
  CHECK_FALSE(writer.append(record_of(0)));  // nothing after a failure
}

TEST(JournalWriter, AFileThatCannotBeCreatedIsAFailureNamingIt) {
  JournalWriter writer;
  CHECK_FALSE(writer.open("/nonexistent/dir/job.journal", start_of()));
  STRCMP_EQUAL("/nonexistent/dir/job.journal: cannot be created: No such file or directory", writer.error().c_str());
}

// The machine thread's target is queued, not written, by append_machine_command (it must not wait
// on the file); once written out it is in the file with every cycle record buffered before it, and
// only then does the machine thread see it written: a crash of the program after the target was
// sent cannot lose it.
TEST(JournalWriter, AMachineCommandCountsAsWrittenOnlyOnceItIsInTheFileWithEverythingBeforeIt) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  for (int i = 0; i < 5; ++i) {
    CHECK_TRUE(writer.append(record_of(static_cast<std::uint64_t>(i))));
  }
  CHECK_TRUE(writer.append_homed(123'456'789));
  CHECK_TRUE(writer.machine_commands_written());  // nothing queued yet
  CHECK_TRUE(writer.append_machine_command(command_of(41)));
  CHECK_FALSE(writer.machine_commands_written());  // queued: not to be sent yet
  CHECK_TRUE(writer.write_machine_commands());     // the records thread's look
  CHECK_TRUE(writer.machine_commands_written());
  // Read while still open, as after a SIGKILL right here (no close, no sync).
  Seen seen;
  const std::vector<std::uint8_t> bytes = file.bytes();
  const JournalReadResult read = read_journal(bytes.data(), bytes.size(), seen.visitor());
  CHECK_TRUE(read.ok);
  LONGS_EQUAL(5, seen.cycles.size());
  LONGS_EQUAL(1, seen.homings.size());
  LONGS_EQUAL(123'456'789, seen.homings[0]);
  LONGS_EQUAL(1, seen.commands.size());
  const auto& c = seen.commands[0];
  const auto want = command_of(41);
  LONGS_EQUAL(41, c.update);
  LONGS_EQUAL(want.time_ns, c.time_ns);
  for (int i = 0; i < 3; ++i) {
    LONGS_EQUAL(want.motor_target[i], c.motor_target[i]);
    LONGS_EQUAL(want.order[i], c.order[i]);
    CHECK(want.target_tip_mm[i] == c.target_tip_mm[i]);
  }
  LONGS_EQUAL(1, writer.machine_records());
}

// A resumed job carries on in the same file: the torn tail is cut off, the Resume record follows the
// last whole record, and the records after it read on.
TEST(JournalWriter, ResumingCutsTheTornTailAndCarriesOnInTheSameFile) {
  TempJournal file;
  write_job(file.path, 120);  // cycles 0-99, 100-119
  std::vector<std::uint8_t> whole = file.bytes();
  {
    std::ofstream cut(file.path, std::ios::binary | std::ios::trunc);
    cut.write(reinterpret_cast<const char*>(whole.data()), static_cast<std::streamsize>(whole.size() - 30));
  }
  Seen before;
  const JournalReadResult first = read_journal_file(file.path, before.visitor());
  CHECK_TRUE(first.ok);
  CHECK(first.tail_bytes > 0);
  LONGS_EQUAL(100, before.cycles.size());
  JournalWriter writer;
  JournalResume resume;
  resume.segment = 1;
  resume.unix_time_ns = 77;
  resume.script_s = 12.5;
  resume.approach_s = 40.25;
  resume.program = "stencil-sim";
  CHECK_TRUE(writer.open_to_resume(file.path, first.good_bytes, resume));
  for (std::uint64_t c = 0; c < 5; ++c) {
    CHECK_TRUE(writer.append(record_of(c)));
  }
  CHECK_TRUE(writer.append_end(5, SafeReason::None));
  CHECK_TRUE(writer.close());
  Seen after;
  const JournalReadResult second = read_journal_file(file.path, after.visitor());
  CHECK_TRUE(second.ok);
  LONGS_EQUAL(0, second.tail_bytes);
  LONGS_EQUAL(105, after.cycles.size());
  // The resumed run reads as written, its times among them (its steps count afresh, as its writer's).
  CHECK_TRUE(after.cycles[100].tool_recorded);  // a run's first cycle is a key: nothing before it needed
  for (std::uint64_t c = 0; c < 5; ++c) {
    check_same(record_of(c), after.cycles[100 + c]);
  }
  LONGS_EQUAL(1, after.resumes.size());
  LONGS_EQUAL(1, after.resumes[0].segment);
  LONGS_EQUAL(77, after.resumes[0].unix_time_ns);
  CHECK(after.resumes[0].script_s == 12.5 && after.resumes[0].approach_s == 40.25);
  STRCMP_EQUAL("stencil-sim", after.resumes[0].program.c_str());
  LONGS_EQUAL(1, after.endings.size());  // the first run was cut off: only the second ended in order
  LONGS_EQUAL(5, after.endings[0].first);
  CHECK(after.endings[0].second == SafeReason::None);
}

// Carrying a version 2 journal on would mix versions in one file: refused, naming both.
TEST(JournalWriter, AVersion2JournalIsNotCarriedOn) {
  TempJournal file;
  OldJournal version2(2);
  for (int i = 0; i < 20; ++i) {
    version2.cycle(record_of(static_cast<std::uint64_t>(i), i >= 10 ? SafeReason::PoseJump : SafeReason::None));
  }
  version2.write(file.path);
  JournalWriter writer;
  JournalResume resume;
  resume.segment = 1;
  CHECK_FALSE(writer.open_to_resume(file.path, version2.bytes().size(), resume));
  STRCMP_CONTAINS("is a version 2 journal; this program carries on versions 3 to 5 only", writer.error().c_str());
}

// Which build made each run, after its Start and each Resume; a version 3 journal (none, and every
// record of it a version 5 record) is carried on as version 5, its resumed run saying what made it
// and its cycles compact after the old ones.
TEST(JournalWriter, EachRunSaysWhatMadeItAndAVersion3JournalIsCarriedOnAsVersion5) {
  TempJournal file;
  {
    JournalWriter writer;
    JournalStart start = start_of();
    start.provenance = "journal_tests v1 (GNU 12); configuration compiled-in; command: journal_tests";
    CHECK_TRUE(writer.open(file.path, start));
    CHECK_TRUE(writer.append(record_of(0)));
    CHECK_TRUE(writer.close());
  }
  Seen first;
  JournalReadResult read = read_journal_file(file.path, first.visitor());
  CHECK_TEXT(read.ok, read.error.c_str());
  CHECK_EQUAL(1U, first.provenances.size());
  STRCMP_EQUAL("journal_tests v1 (GNU 12); configuration compiled-in; command: journal_tests", first.provenances[0].c_str());
  {
    JournalWriter writer;
    JournalResume resume;
    resume.segment = 1;
    resume.program = "journal_tests";
    resume.provenance = "journal_tests v2; command: journal_tests --resume";
    CHECK_TRUE(writer.open_to_resume(file.path, read.good_bytes, resume));
    CHECK_TRUE(writer.close());
  }
  Seen both;
  read = read_journal_file(file.path, both.visitor());
  CHECK_TEXT(read.ok, read.error.c_str());
  CHECK_EQUAL(2U, both.provenances.size());
  STRCMP_EQUAL("journal_tests v2; command: journal_tests --resume", both.provenances[1].c_str());

  // A version 3 journal: Cycle records, no Provenance.
  OldJournal version3(3);
  for (int i = 0; i < 3; ++i) {
    version3.cycle(record_of(static_cast<std::uint64_t>(i)));
  }
  version3.write(file.path);
  {
    JournalWriter writer;
    JournalResume resume;
    resume.segment = 1;
    resume.provenance = "journal_tests v2";
    CHECK_TRUE(writer.open_to_resume(file.path, version3.bytes().size(), resume));
    CHECK_TRUE(writer.append(record_of(0)));
    CHECK_TRUE(writer.append(record_of(1)));
    CHECK_TRUE(writer.close());
  }
  Seen old;
  read = read_journal_file(file.path, old.visitor());
  CHECK_TEXT(read.ok, read.error.c_str());
  CHECK_EQUAL(1U, old.resumes.size());
  CHECK_EQUAL(5U, old.cycles.size());
  CHECK_FALSE(old.cycles[2].maxima_recorded);  // version 3's
  CHECK_TRUE(old.cycles[4].maxima_recorded);   // the carried-on run's, compact
  check_same(record_of(1), old.cycles[4]);
  CHECK_EQUAL(1U, old.provenances.size());
  STRCMP_EQUAL("journal_tests v2", old.provenances[0].c_str());
  CHECK_EQUAL(5U, file.bytes()[8]);
}
