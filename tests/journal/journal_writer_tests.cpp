// The journal: what is written reads back exactly; a torn tail at any byte is found and ignored,
// never misread; damage that is not a crash's is an error naming the offset; a full disk is a clear
// failure.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>
#include <zlib.h>

#include "firmware/services/journal/journal_bytes.hpp"
#include "firmware/services/journal/journal_drain.hpp"
#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/old_journal.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::JournalRecord;
using stencil::control::SafeReason;
using namespace stencil::journal;

namespace {

JournalRecord record_of(std::uint64_t cycle, SafeReason reason = SafeReason::None) {
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

using stencil::testing::OldJournal;

struct TempJournal {
  std::string path;
  TempJournal() {
    char name[] = "/tmp/journal_tests_XXXXXX";
    const int fd = mkstemp(name);
    if (fd >= 0) {
      close(fd);
    }
    path = name;
  }
  ~TempJournal() { std::remove(path.c_str()); }
  [[nodiscard]] std::vector<std::uint8_t> bytes() const {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
};

JournalStart start_of() {
  JournalStart start;
  start.tables_crc32 = 0xdeadbeef;
  start.triangle_count = 92;
  start.unix_time_ns = 1'796'000'000'000'000'000;
  start.program = "journal_tests";
  start.job = "pattern=raster seed=1";
  return start;
}

// Writes `cycles` records (the last `safe_from` onward in the safe state) and closes.
void write_job(const std::string& path, int cycles, int safe_from = -1) {
  JournalWriter writer;
  CHECK_TRUE(writer.open(path, start_of()));
  for (int i = 0; i < cycles; ++i) {
    const SafeReason reason = safe_from >= 0 && i >= safe_from ? SafeReason::PoseJump : SafeReason::None;
    CHECK_TRUE(writer.append(record_of(static_cast<std::uint64_t>(i), reason)));
  }
  CHECK_TRUE(writer.close());
}

struct Seen {
  int starts = 0;
  std::vector<RecordedCycle> cycles;
  std::vector<std::pair<std::uint64_t, SafeReason>> events;
  std::vector<std::int64_t> homings;
  std::vector<stencil::control::MachineCommandRecord> commands;
  std::vector<JournalResume> resumes;
  std::vector<std::pair<std::uint64_t, SafeReason>> endings;
  JournalStart start;
  std::vector<stencil::control::CommandSource> sources;  // each safe state's
  std::vector<stencil::control::CommandEvent> taken;     // the cycle's commands
  std::vector<std::string> provenances;
  JournalVisitor visitor() {
    JournalVisitor v;
    v.start = [this](const JournalStart& s) {
      ++starts;
      start = s;
    };
    v.cycle = [this](const RecordedCycle& r) { cycles.push_back(r); };
    v.safe_state = [this](std::uint64_t cycle, SafeReason reason) { events.emplace_back(cycle, reason); };
    v.safe_source = [this](std::uint64_t, SafeReason, stencil::control::CommandSource source) { sources.push_back(source); };
    v.command = [this](const stencil::control::CommandEvent& e) { taken.push_back(e); };
    v.homed = [this](std::int64_t t) { homings.push_back(t); };
    v.machine_command = [this](const stencil::control::MachineCommandRecord& c) { commands.push_back(c); };
    v.resume = [this](const JournalResume& r) { resumes.push_back(r); };
    v.end = [this](std::uint64_t c, SafeReason reason) { endings.emplace_back(c, reason); };
    v.provenance = [this](const std::string& text) { provenances.push_back(text); };
    return v;
  }
};

// `seen` is `a` as written: bit for bit (a replay must be exact), its tool whole or its check.
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

// Where each whole record starts, and where the last one ends.
std::vector<std::size_t> record_starts(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::size_t> starts;
  JournalVisitor offsets;
  offsets.offset = [&](std::size_t offset) { starts.push_back(offset); };
  const JournalReadResult read = read_journal(bytes.data(), bytes.size(), offsets);
  CHECK_TEXT(read.ok, read.error.c_str());
  starts.push_back(read.good_bytes);
  return starts;
}

stencil::control::MachineCommandRecord command_of(std::uint64_t update) {
  return {update, static_cast<std::int64_t>(update) * 33'333'333, {-1200, 35, static_cast<std::int32_t>(update)},
          {2, 0, 3}, {25.125, 12.0 + 1e-7 * static_cast<double>(update), 3.0}};
}

}  // namespace

TEST_GROUP(Journal){};

TEST(Journal, WhatIsWrittenReadsBackExactlyWithTheStartAndTheSafeStateEvent) {
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

TEST(Journal, TheSafeStateEventIsOnTheDiskTheMomentItIsAppended) {
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

TEST(Journal, SyncsWhenASecondHasPassedAndNotBefore) {
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

// A crash can cut the file anywhere: every cut inside the last record (cycles 100-149) reads every
// record before it and reports the rest as the tail; none is misread.
TEST(Journal, ATornTailAtAnyByteIsIgnoredAndEverythingBeforeItReads) {
  TempJournal file;
  write_job(file.path, 150);
  const std::vector<std::uint8_t> whole = file.bytes();
  const std::vector<std::size_t> starts = record_starts(whole);
  LONGS_EQUAL(4, starts.size());  // start, two Cycles records, the end of the file
  const std::size_t last = whole.size() - starts[2];
  for (std::size_t cut = 1; cut < last; ++cut) {
    Seen seen;
    const JournalReadResult read = read_journal(whole.data(), whole.size() - cut, seen.visitor());
    CHECK_TRUE(read.ok);
    LONGS_EQUAL(100, seen.cycles.size());
    LONGS_EQUAL(last - cut, read.tail_bytes);
    CHECK_FALSE(read.tail.empty());
    check_same(record_of(99), seen.cycles.back());
  }
}

TEST(Journal, AFlippedBitWithRecordsAfterItIsDamageThatSaysWhereAndInTheLastRecordATornTail) {
  TempJournal file;
  write_job(file.path, 350);  // cycles 0-99, 100-199, 200-299, 300-349
  const std::vector<std::uint8_t> whole = file.bytes();
  const std::vector<std::size_t> starts = record_starts(whole);
  LONGS_EQUAL(6, starts.size());
  const std::size_t second = starts[2];
  std::vector<std::uint8_t> bytes = whole;
  bytes[second + 20] ^= 0x10;  // inside the second Cycles record's payload
  Seen seen;
  JournalReadResult read = read_journal(bytes.data(), bytes.size(), seen.visitor());
  CHECK_FALSE(read.ok);
  LONGS_EQUAL(100, seen.cycles.size());  // what came before it was read
  LONGS_EQUAL(second, read.good_bytes);
  STRCMP_CONTAINS(("journal offset " + std::to_string(second) + ": a record whose CRC-32 does not match, with " +
                   std::to_string(whole.size() - starts[3]) + " bytes after it")
                      .c_str(),
                  read.error.c_str());
  const std::size_t last = starts[4];
  bytes = whole;
  bytes[last + 20] ^= 0x10;  // the last record: a torn write
  Seen seen_last;
  read = read_journal(bytes.data(), bytes.size(), seen_last.visitor());
  CHECK_TRUE(read.ok);
  LONGS_EQUAL(300, seen_last.cycles.size());
  LONGS_EQUAL(whole.size() - last, read.tail_bytes);
  STRCMP_CONTAINS("a last record whose CRC-32 does not match", read.tail.c_str());
}

TEST(Journal, NotAJournalOrAnotherVersionIsAnErrorNamingWhatWasExpected) {
  const std::uint8_t text[] = "t_s,x_mm,y_mm,z_mm\n";
  Seen seen;
  JournalReadResult read = read_journal(text, sizeof text, seen.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("not a journal (expected the magic STENCILJ", read.error.c_str());
  TempJournal file;
  write_job(file.path, 1);
  std::vector<std::uint8_t> bytes = file.bytes();
  bytes[8] = 9;
  read = read_journal(bytes.data(), bytes.size(), seen.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("journal offset 8: version 9; this program reads versions 2 to 5", read.error.c_str());
  read = read_journal_file("/nonexistent/journal", seen.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_EQUAL("/nonexistent/journal: cannot be read", read.error.c_str());
  read = read_journal_file("/dev/zero", seen.visitor());  // endless: refused before reading
  CHECK_FALSE(read.ok);
  STRCMP_EQUAL("/dev/zero: not a regular file (a journal is one)", read.error.c_str());
}

TEST(Journal, AFullDiskIsAFailureThatSaysSo) {
  JournalWriter writer;
  // /dev/full takes the open and refuses every write with ENOSPC.
  CHECK_FALSE(writer.open("/dev/full", start_of()));
  STRCMP_CONTAINS("/dev/full: write failed: No space left on device", writer.error().c_str());
  CHECK_FALSE(writer.append(record_of(0)));  // nothing after a failure
}

TEST(Journal, AFileThatCannotBeCreatedIsAFailureNamingIt) {
  JournalWriter writer;
  CHECK_FALSE(writer.open("/nonexistent/dir/job.journal", start_of()));
  STRCMP_EQUAL("/nonexistent/dir/job.journal: cannot be created: No such file or directory", writer.error().c_str());
}

// The journal thread's side: a record that cannot be written asks the cycle to stop, and a full
// command ring does not lose that request.
TEST(Journal, AWriteFailureReachesTheCycleEvenThroughAFullCommandRing) {
  JournalWriter never_opened;  // every append fails
  stencil::control::CommandRing commands;
  stencil::control::JournalRing ring;
  JournalDrain drain(&never_opened, commands);
  while (commands.push({stencil::control::CommandKind::Reset})) {
  }
  CHECK(ring.push(record_of(0)));
  drain.drain(ring);
  CHECK_TRUE(drain.failed());
  stencil::control::Command command{};
  int journal_failed = 0;
  while (commands.pop(command)) {  // the cycle takes its commands
    journal_failed += command.kind == stencil::control::CommandKind::JournalFailed ? 1 : 0;
  }
  LONGS_EQUAL(0, journal_failed);  // there was no room
  drain.drain(ring);               // the next look
  CHECK(commands.pop(command));
  CHECK(command.kind == stencil::control::CommandKind::JournalFailed);
  drain.drain(ring);
  CHECK_FALSE(commands.pop(command));  // once
}

// The machine thread's target is queued, not written, by append_machine_command (it must not wait
// on the file); once written out it is in the file with every cycle record buffered before it, and
// only then does the machine thread see it written: a crash of the program after the target was
// sent cannot lose it.
TEST(Journal, AMachineCommandCountsAsWrittenOnlyOnceItIsInTheFileWithEverythingBeforeIt) {
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
TEST(Journal, ResumingCutsTheTornTailAndCarriesOnInTheSameFile) {
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

TEST(Journal, AMachineCommandThatNamesNoAxisOrAnInfiniteTargetIsAnErrorNamingTheOffset) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  auto bad = command_of(1);
  bad.order[1] = 7;
  CHECK_TRUE(writer.append_machine_command(bad));
  CHECK_TRUE(writer.append_machine_command(command_of(2)));
  CHECK_TRUE(writer.close());
  Seen seen;
  const JournalReadResult read = read_journal_file(file.path, seen.visitor());
  CHECK_FALSE(read.ok);
  CHECK(read.error.find("journal offset ") != std::string::npos);
  CHECK(read.error.find("leg order") != std::string::npos);
  LONGS_EQUAL(0, seen.commands.size());
}

// Issue 22: each command the cycle took is a record of its own, before the record of its cycle, and
// the safe state says where it came from.
TEST(Journal, TheDrainWritesEachCommandBeforeItsCyclesRecordAndTheSafeStateWithItsSource) {
  using stencil::control::CommandEvent;
  using stencil::control::CommandKind;
  using stencil::control::CommandOutcome;
  using stencil::control::CommandSource;
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  stencil::control::CommandRing commands;
  stencil::control::JournalRing ring;
  stencil::control::CommandEventRing taken;
  JournalDrain drain(&writer, commands);
  drain.take_commands_from(&taken);
  // Cycle 3 took a speed change, cycle 5 a pause and a stop (from the display); the drain looks
  // after cycle 4, when cycle 5's commands are out and its record is not yet.
  for (std::uint64_t cycle = 1; cycle <= 4; ++cycle) {
    if (cycle == 3) {
      CHECK(taken.push(CommandEvent{3, 3'000'017, 2, CommandKind::SetSpeedLimit, CommandSource::Display,
                                    CommandOutcome::Clamped, 50.0, 1.0}));
    }
    CHECK(ring.push(record_of(cycle)));
  }
  CHECK(taken.push(CommandEvent{5, 5'000'017, 4, CommandKind::Pause, CommandSource::Display, CommandOutcome::Done, 0.0, 0.0}));
  CHECK(taken.push(CommandEvent{5, 5'000'017, 4, CommandKind::Stop, CommandSource::Display, CommandOutcome::Done, 0.0, 0.0}));
  drain.drain(ring);
  JournalRecord stopped = record_of(5, SafeReason::Stopped);
  stopped.safe_source = CommandSource::Display;
  CHECK(ring.push(stopped));
  drain.drain(ring, true);
  CHECK_FALSE(drain.failed());
  LONGS_EQUAL(3, drain.commands().size());
  CHECK_TRUE(writer.close());

  std::vector<std::string> order;
  JournalVisitor visit;
  visit.cycle = [&](const RecordedCycle& r) { order.push_back("cycle " + std::to_string(r.record.cycle)); };
  visit.command = [&](const CommandEvent& e) {
    order.push_back(std::string(stencil::control::command_kind_name(e.kind)) + " " + std::to_string(e.cycle));
  };
  visit.safe_source = [&](std::uint64_t cycle, SafeReason reason, CommandSource source) {
    order.push_back(std::string("safe ") + stencil::control::safe_reason_name(reason) + " " + std::to_string(cycle) +
                    " from " + stencil::control::command_source_name(source));
  };
  Seen seen;
  JournalVisitor values = seen.visitor();
  CHECK_TRUE(read_journal_file(file.path, visit).ok);
  CHECK_TRUE(read_journal_file(file.path, values).ok);
  std::string joined;
  for (const std::string& item : order) {
    joined += item + "; ";
  }
  STRCMP_EQUAL("cycle 1; cycle 2; set_speed_limit 3; cycle 3; cycle 4; pause 5; stop 5; cycle 5; safe stopped 5 from display; ",
               joined.c_str());
  LONGS_EQUAL(3, seen.taken.size());
  const CommandEvent& speed = seen.taken[0];
  LONGS_EQUAL(2, speed.queued_after_cycle);
  CHECK(speed.outcome == CommandOutcome::Clamped);
  DOUBLES_EQUAL(50.0, speed.asked, 0.0);
  DOUBLES_EQUAL(1.0, speed.applied, 0.0);
  CHECK(speed.source == CommandSource::Display);
  CHECK(speed.time_ns == 3'000'017);
}

TEST(Journal, AVersion2JournalStillReadsButIsNotCarriedOn) {
  TempJournal file;
  // As version 2 wrote it: a Cycle record per cycle, a safe-state record without its source.
  OldJournal version2(2);
  for (int i = 0; i < 20; ++i) {
    version2.cycle(record_of(static_cast<std::uint64_t>(i), i >= 10 ? SafeReason::PoseJump : SafeReason::None));
  }
  const std::vector<std::uint8_t>& old = version2.bytes();
  Seen seen;
  const JournalReadResult read = read_journal(old.data(), old.size(), seen.visitor());
  CHECK_TEXT(read.ok, read.error.c_str());
  LONGS_EQUAL(20, seen.cycles.size());
  for (int i = 0; i < 20; ++i) {
    const RecordedCycle& cycle = seen.cycles[static_cast<std::size_t>(i)];
    CHECK_TRUE(cycle.tool_recorded);
    CHECK_FALSE(cycle.maxima_recorded);  // version 5's
    JournalRecord want = record_of(static_cast<std::uint64_t>(i), i >= 10 ? SafeReason::PoseJump : SafeReason::None);
    check_same(want, cycle);
  }
  LONGS_EQUAL(1, seen.events.size());
  LONGS_EQUAL(1, seen.sources.size());
  CHECK(seen.sources[0] == stencil::control::CommandSource::Cycle);
  // Carrying it on would mix versions in one file: refused, naming both.
  version2.write(file.path);
  JournalWriter writer;
  JournalResume resume;
  resume.segment = 1;
  CHECK_FALSE(writer.open_to_resume(file.path, read.good_bytes, resume));
  STRCMP_CONTAINS("is a version 2 journal; this program carries on versions 3 to 5 only", writer.error().c_str());
}

// Which build made each run, after its Start and each Resume; a version 3 journal (none, and every
// record of it a version 5 record) is carried on as version 5, its resumed run saying what made it
// and its cycles compact after the old ones.
TEST(Journal, EachRunSaysWhatMadeItAndAVersion3JournalIsCarriedOnAsVersion5) {
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
  // A Cycles record in a version 4 journal is damage.
  std::vector<std::uint8_t> bytes = file.bytes();
  bytes[8] = 4;
  Seen mixed;
  read = read_journal(bytes.data(), bytes.size(), mixed.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("a cycles record in a version 4 journal (version 5 has them)", read.error.c_str());

  // A provenance record in a version 3 journal is damage, named by its offset.
  {
    JournalWriter writer;
    JournalStart start = start_of();
    start.provenance = "x";
    CHECK_TRUE(writer.open(file.path, start));
    CHECK_TRUE(writer.close());
  }
  bytes = file.bytes();
  bytes[8] = 3;
  Seen damaged;
  read = read_journal(bytes.data(), bytes.size(), damaged.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("a provenance record of 3 bytes in a version 3 journal", read.error.c_str());

  // Only right after its run's start or resume, once; its length must hold its text.
  {
    JournalWriter writer;
    JournalStart start = start_of();
    start.provenance = "made by";
    CHECK_TRUE(writer.open(file.path, start));
    CHECK_TRUE(writer.append(record_of(0)));
    CHECK_TRUE(writer.close());
  }
  bytes = file.bytes();
  const std::size_t start_record = kFileHeaderBytes;
  const std::size_t start_length = bytes[start_record] + (std::size_t{bytes[start_record + 1]} << 8U);
  const std::size_t provenance_at = start_record + kRecordOverheadBytes + start_length;
  const std::size_t provenance_length = kRecordOverheadBytes + 2 + 7;
  CHECK_EQUAL(static_cast<int>(RecordType::Provenance), bytes[provenance_at + 4]);
  std::vector<std::uint8_t> twice(bytes.begin(), bytes.begin() + static_cast<long>(provenance_at + provenance_length));
  twice.insert(twice.end(), bytes.begin() + static_cast<long>(provenance_at), bytes.end());
  Seen repeated;
  read = read_journal(twice.data(), twice.size(), repeated.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS(("journal offset " + std::to_string(provenance_at + provenance_length) +
                   ": a provenance record not right after a start or resume record").c_str(), read.error.c_str());
  std::vector<std::uint8_t> short_text = bytes;
  short_text[provenance_at + 5] = 9;  // the text's length: 9 of the 7 bytes there
  const uLong crc = crc32(crc32(0L, Z_NULL, 0), short_text.data() + provenance_at, static_cast<uInt>(5 + 2 + 7));
  for (int b = 0; b < 4; ++b) {
    short_text[provenance_at + 5 + 2 + 7 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(crc >> (8 * b));
  }
  Seen wrong;
  read = read_journal(short_text.data(), short_text.size(), wrong.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("a provenance record of 9 bytes that does not hold its text", read.error.c_str());
}

// A run's cycles are all in one form; a Cycles record holds at least one. Anything else is damage.
TEST(Journal, ARunOfCompactCyclesWithAWholeCycleRecordOrAnEmptyCyclesRecordIsAnErrorNamingTheOffset) {
  TempJournal file;
  write_job(file.path, 3);
  const std::vector<std::uint8_t> whole = file.bytes();
  const auto appended = [&](RecordType type, const ByteWriter& payload) {
    ByteWriter record;
    record.u32(static_cast<std::uint32_t>(payload.size()));
    record.u8(static_cast<std::uint8_t>(type));
    record.bytes(payload.data(), payload.size());
    record.u32(static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), record.data(), static_cast<uInt>(record.size()))));
    std::vector<std::uint8_t> bytes = whole;
    bytes.insert(bytes.end(), record.data(), record.data() + record.size());
    return bytes;
  };
  ByteWriter cycle;
  encode_cycle(record_of(3), cycle);
  std::vector<std::uint8_t> bytes = appended(RecordType::Cycle, cycle);
  JournalReadResult read = read_journal(bytes.data(), bytes.size(), {});
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS(("journal offset " + std::to_string(whole.size()) + ": a cycle record of 106 bytes in a run of compact cycles").c_str(),
                  read.error.c_str());
  bytes = appended(RecordType::Cycles, ByteWriter{});
  read = read_journal(bytes.data(), bytes.size(), {});
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("an empty cycles record (expected at least one cycle)", read.error.c_str());
}

TEST(Journal, ACommandRecordOutOfRangeIsAnErrorNamingTheOffset) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  CHECK_TRUE(writer.append_command({1, 17, 0, stencil::control::CommandKind::Pause, stencil::control::CommandSource::Display,
                                    stencil::control::CommandOutcome::Done, 0.0, 0.0}));
  CHECK_TRUE(writer.close());
  std::vector<std::uint8_t> bytes = file.bytes();
  JournalVisitor offsets;
  std::vector<std::size_t> starts;
  offsets.offset = [&](std::size_t offset) { starts.push_back(offset); };
  CHECK_TRUE(read_journal(bytes.data(), bytes.size(), offsets).ok);
  const std::size_t at = starts.back();
  LONGS_EQUAL(static_cast<int>(RecordType::Command), bytes[at + 4]);
  bytes[at + 5 + 24] = 99;  // the kind
  const std::size_t length = 5 + kCommandPayloadBytes;
  const uLong crc = crc32(crc32(0L, Z_NULL, 0), bytes.data() + at, static_cast<uInt>(length));
  for (int b = 0; b < 4; ++b) {
    bytes[at + length + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(crc >> (8 * b));
  }
  const JournalReadResult read = read_journal(bytes.data(), bytes.size(), {});
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS(("journal offset " + std::to_string(at + 5 + 24) + ": a command record's kind is 99 (expected below 8)").c_str(),
                  read.error.c_str());
}
