// The machine thread's side of the journal: it records each target without waiting for the records
// thread's writes (slow storage must not make a machine update late), every target reaches the
// file in order, and a target the machine side is told is written is in the file.
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "firmware/services/journal/journal_drain.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/fakes/fake_journal_storage.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using stencil::control::JournalRecord;
using stencil::control::MachineCommandRecord;
using stencil::test::FakeJournalStorage;
using namespace stencil::journal;
using namespace std::chrono_literals;

namespace {

struct TempJournal {
  std::string path;
  TempJournal() {
    char name[] = "/tmp/machine_journal_tests_XXXXXX";
    const int fd = mkstemp(name);
    if (fd >= 0) {
      close(fd);
    }
    path = name;
  }
  ~TempJournal() { std::remove(path.c_str()); }
  TempJournal(const TempJournal&) = delete;
  TempJournal& operator=(const TempJournal&) = delete;
};

JournalStart start_of() {
  JournalStart start;
  start.tables_crc32 = 0x1234abcd;
  start.triangle_count = 92;
  start.program = "machine_journal_tests";
  start.job = "pattern=raster";
  return start;
}

JournalRecord cycle_record(std::uint64_t cycle) {
  JournalRecord r{};
  r.cycle = cycle;
  r.time_ns = static_cast<std::int64_t>(cycle) * 1'000'000;
  r.virtual_tip_mm[0] = 25.0;
  r.virtual_tip_mm[1] = 12.5;
  r.virtual_tip_mm[2] = 7.0;
  return r;
}

MachineCommandRecord command_of(std::uint64_t update) {
  return {update, static_cast<std::int64_t>(update) * 33'333'333, {-1200, 35, static_cast<std::int32_t>(update)},
          {2, 0, 1}, {25.125, 12.0 + 1e-3 * static_cast<double>(update), 3.0}};
}

// Every machine command in the file (read as after a crash: the writer may still be open).
std::vector<MachineCommandRecord> commands_in(const std::string& path) {
  std::vector<MachineCommandRecord> commands;
  JournalVisitor visit;
  visit.machine_command = [&](const MachineCommandRecord& c) { commands.push_back(c); };
  const JournalReadResult read = read_journal_file(path, visit);
  CHECK_TEXT(read.ok, read.error.c_str());
  return commands;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

// The records and machine threads allocate beside the test's, which CppUTest's leak detector does
// not take (it is not thread-safe): it is off here, as for the display's server threads, and the ASan
// preset's LeakSanitizer checks these tests instead.
TEST_GROUP(MachineJournal) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

// Issue 18, item 10: the records thread holds the writer's lock across its write(); on storage that
// takes 200 ms for it, the machine thread's record of its next target must not wait those 200 ms (a
// machine update that late misses its deadline, which is a fault). It returns at once, and the
// target is in the file after the records thread's next look.
TEST(MachineJournal, RecordingATargetDoesNotWaitForTheRecordsThreadsSlowWrite) {
  TempJournal file;
  FakeJournalStorage storage;
  JournalWriter writer(storage);
  CHECK_TRUE(writer.open(file.path, start_of()));
  stencil::control::CommandRing commands;
  stencil::control::JournalRing cycles;
  JournalDrain records(&writer, commands);
  MachineJournal machine(writer);

  constexpr auto kSlowWrite = 200ms;
  storage.make_writes_take(kSlowWrite);
  const int writes_before = storage.writes_begun();
  for (std::uint64_t cycle = 0; cycle < kCyclesPerRecord; ++cycle) {  // a whole Cycles record to write
    CHECK(cycles.push(cycle_record(cycle)));
  }
  bool synced = false;
  std::thread records_thread([&] {
    records.drain(cycles);     // buffers the cycles' record
    synced = writer.sync();    // and writes it out: 200 ms inside write(), the writer's lock held
  });
  while (storage.writes_begun() == writes_before) {
    std::this_thread::yield();  // until the records thread is inside its slow write
  }
  const auto before = std::chrono::steady_clock::now();
  const bool recorded = machine.command(command_of(7));
  const double took_ms = ms_since(before);
  records_thread.join();
  storage.make_writes_take(0ns);

  CHECK_TRUE(synced);
  CHECK_TRUE(recorded);
  std::printf("\n  the machine thread's record took %.3f ms beside a %lld ms write\n", took_ms,
              static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(kSlowWrite).count()));
  // Within microseconds on an idle host; 20 ms leaves room for a loaded CI host and is still a tenth
  // of the write it must not wait for.
  CHECK_TEXT(took_ms < 20.0, ("the record took " + std::to_string(took_ms) + " ms").c_str());
  records.drain(cycles);  // the records thread's next look
  const std::vector<MachineCommandRecord> in_file = commands_in(file.path);
  LONGS_EQUAL(1, in_file.size());
  LONGS_EQUAL(7, in_file[0].update);
  CHECK_TRUE(writer.close());
}

// The machine side sends the target it queued only once written() says so: at that moment the target
// is in the file (read as after a SIGKILL there), whatever the storage does. The records thread runs
// its loop as on the rig (drain, sync when due, wait for the next target); the storage takes 5 ms
// per write and now and then 150 ms. At the end every target is in the file once, in order, and so is
// every cycle record.
TEST(MachineJournal, ATargetIsInTheFileWhenTheMachineSideIsToldItIsWrittenAndAllArriveInOrder) {
  TempJournal file;
  FakeJournalStorage storage;
  JournalWriter writer(storage);
  CHECK_TRUE(writer.open(file.path, start_of()));
  stencil::control::CommandRing commands;
  stencil::control::JournalRing cycles;
  JournalDrain records(&writer, commands);
  MachineJournal machine(writer);
  storage.make_writes_take(5ms);

  std::atomic<bool> stop{false};
  std::thread records_thread([&] {
    while (!stop.load()) {
      records.drain(cycles);
      records.sync_if_due();
      records.wait(50ms);
    }
  });
  constexpr std::uint64_t kCycles = 2000;
  std::thread cycle_thread([&] {
    for (std::uint64_t cycle = 0; cycle < kCycles; ++cycle) {
      while (!cycles.push(cycle_record(cycle))) {
        std::this_thread::sleep_for(1ms);  // the test's cycle waits where the real one would fault
      }
      std::this_thread::sleep_for(100us);
    }
  });
  constexpr std::uint64_t kTargets = 40;
  std::vector<std::uint64_t> last_in_file_when_written;
  int refused = 0;
  for (std::uint64_t update = 0; update < kTargets; ++update) {
    storage.make_writes_take(update % 10 == 5 ? 150ms : 5ms);
    if (!machine.command(command_of(update))) {
      ++refused;
      continue;
    }
    while (!machine.written()) {
      std::this_thread::sleep_for(1ms);  // the machine side holds the mill, update after update
    }
    const std::vector<MachineCommandRecord> in_file = commands_in(file.path);
    last_in_file_when_written.push_back(in_file.empty() ? ~0ULL : in_file.back().update);
  }
  cycle_thread.join();
  stop.store(true);
  records_thread.join();
  records.drain(cycles);
  storage.make_writes_take(0ns);
  CHECK_TRUE(writer.close());

  LONGS_EQUAL(0, refused);
  CHECK_FALSE(records.failed());
  LONGS_EQUAL(kTargets, last_in_file_when_written.size());
  for (std::uint64_t update = 0; update < kTargets; ++update) {
    LONGS_EQUAL(update, last_in_file_when_written[update]);  // written() meant: in the file, this one last
  }
  std::vector<MachineCommandRecord> targets;
  std::vector<std::uint64_t> cycle_numbers;
  JournalVisitor visit;
  visit.machine_command = [&](const MachineCommandRecord& c) { targets.push_back(c); };
  visit.cycle = [&](const stencil::journal::RecordedCycle& r) { cycle_numbers.push_back(r.record.cycle); };
  const JournalReadResult read = read_journal_file(file.path, visit);
  CHECK_TEXT(read.ok, read.error.c_str());
  LONGS_EQUAL(kTargets, targets.size());
  for (std::uint64_t update = 0; update < kTargets; ++update) {
    const MachineCommandRecord want = command_of(update);
    LONGS_EQUAL(update, targets[update].update);
    LONGS_EQUAL(want.motor_target[2], targets[update].motor_target[2]);
    CHECK(want.target_tip_mm[1] == targets[update].target_tip_mm[1]);
  }
  LONGS_EQUAL(kCycles, cycle_numbers.size());
  for (std::uint64_t cycle = 0; cycle < kCycles; ++cycle) {
    LONGS_EQUAL(cycle, cycle_numbers[cycle]);
  }
  LONGS_EQUAL(kTargets, writer.machine_records());
  LONGS_EQUAL(0, writer.machine_commands_refused());
}

// A machine side that queued without waiting fills the ring: the target that finds it full is
// refused (so the machine side does not send it and stops on a journal fault), counted, and never
// in the file; every target queued before it is, in order.
TEST(MachineJournal, AFullRingRefusesTheTargetCountsItAndKeepsEveryTargetBeforeIt) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  MachineJournal machine(writer);
  for (std::uint64_t update = 0; update < JournalWriter::kMachineRingCapacity; ++update) {
    CHECK_TRUE(machine.command(command_of(update)));
  }
  CHECK_FALSE(machine.command(command_of(JournalWriter::kMachineRingCapacity)));
  LONGS_EQUAL(1, writer.machine_commands_refused());
  CHECK_FALSE(machine.written());
  CHECK_TRUE(writer.write_machine_commands());  // the records thread's next look
  CHECK_TRUE(machine.written());
  const std::vector<MachineCommandRecord> in_file = commands_in(file.path);
  LONGS_EQUAL(JournalWriter::kMachineRingCapacity, in_file.size());
  for (std::uint64_t update = 0; update < in_file.size(); ++update) {
    LONGS_EQUAL(update, in_file[update].update);
  }
  CHECK_TRUE(writer.close());
}

// Storage that refuses the write (a full disk): the queued target never counts as written, so the
// machine side never sends it; the cycle is told (journal_failed); later targets are refused.
TEST(MachineJournal, ATargetThatCannotBeWrittenIsNeverWrittenAndTheCycleIsTold) {
  TempJournal file;
  FakeJournalStorage storage;
  JournalWriter writer(storage);
  CHECK_TRUE(writer.open(file.path, start_of()));
  stencil::control::CommandRing commands;
  stencil::control::JournalRing cycles;
  JournalDrain records(&writer, commands);
  MachineJournal machine(writer);
  storage.fail_writes_with(ENOSPC);
  CHECK_TRUE(machine.command(command_of(3)));
  records.drain(cycles);
  CHECK_TRUE(records.failed());
  CHECK_FALSE(machine.written());
  stencil::control::Command command{};
  CHECK_TRUE(commands.pop(command));
  CHECK(command.kind == stencil::control::CommandKind::JournalFailed);
  CHECK_FALSE(machine.command(command_of(4)));
  STRCMP_CONTAINS("write failed: No space left on device", writer.error().c_str());
  storage.fail_writes_with(0);
  CHECK_FALSE(writer.close());
  LONGS_EQUAL(0, commands_in(file.path).size());
}

// The records thread waits between looks; a target queued wakes it at once rather than after its
// 50 ms (or here a second), so the machine side can send it at its next update.
TEST(MachineJournal, AQueuedTargetWakesTheRecordsThreadAtOnce) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  stencil::control::CommandRing commands;
  stencil::control::JournalRing cycles;
  JournalDrain records(&writer, commands);
  MachineJournal machine(writer);
  std::atomic<bool> waiting{false};
  double waited_ms = 0.0;
  std::thread records_thread([&] {
    waiting.store(true);
    const auto before = std::chrono::steady_clock::now();
    records.wait(1s);
    waited_ms = ms_since(before);
    records.drain(cycles);
  });
  while (!waiting.load()) {
    std::this_thread::yield();
  }
  std::this_thread::sleep_for(20ms);
  CHECK_TRUE(machine.command(command_of(1)));
  records_thread.join();
  CHECK_TEXT(waited_ms < 500.0, ("the records thread waited " + std::to_string(waited_ms) + " ms").c_str());
  CHECK_TRUE(machine.written());
  LONGS_EQUAL(1, commands_in(file.path).size());
  // With nothing queued, the wait is the whole timeout.
  const auto before = std::chrono::steady_clock::now();
  records.wait(30ms);
  CHECK(ms_since(before) >= 29.0);
  CHECK_TRUE(writer.close());
}

// stencil-sim --fast runs the machine update and the records on one thread: its recorder writes the
// target through before command() returns, so the target is sent in the same update as before.
TEST(MachineJournal, TheInlineRecorderHasTheTargetInTheFileBeforeCommandReturns) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  InlineMachineJournal machine(writer);
  CHECK_TRUE(machine.homed(5));
  CHECK_TRUE(machine.command(command_of(9)));
  CHECK_TRUE(machine.written());
  const std::vector<MachineCommandRecord> in_file = commands_in(file.path);
  LONGS_EQUAL(1, in_file.size());
  LONGS_EQUAL(9, in_file[0].update);
  CHECK_TRUE(writer.close());
}

// The fake storage itself: it passes bytes through, takes the time it is told, and fails as told.
TEST(MachineJournal, TheFakeStorageWritesThroughTakesItsTimeAndFailsAsTold) {
  TempJournal file;
  const int fd = ::open(file.path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  CHECK(fd >= 0);
  FakeJournalStorage storage;
  const std::uint8_t bytes[3] = {1, 2, 3};
  LONGS_EQUAL(3, storage.write(fd, bytes, 3));
  storage.make_writes_take(30ms);
  const auto before = std::chrono::steady_clock::now();
  LONGS_EQUAL(3, storage.write(fd, bytes, 3));
  CHECK(ms_since(before) >= 29.0);
  storage.make_writes_take(0ns);
  storage.fail_writes_with(EIO);
  LONGS_EQUAL(-1, storage.write(fd, bytes, 3));
  LONGS_EQUAL(EIO, errno);
  LONGS_EQUAL(0, storage.fsync(fd));
  LONGS_EQUAL(3, storage.writes_begun());
  LONGS_EQUAL(3, storage.writes_done());
  LONGS_EQUAL(1, storage.syncs());
  ::close(fd);
  std::ifstream in(file.path, std::ios::binary);
  const std::vector<char> content{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  LONGS_EQUAL(6, content.size());
}
