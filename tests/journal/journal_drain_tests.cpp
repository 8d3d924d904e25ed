// JournalDrain (journal_drain.hpp), the records thread's loop body: a record that cannot be written
// asks the cycle to stop, once, even through a full command ring; each command the cycle took goes
// in the file before its cycle's record; what it drained is kept for the report and shown to a
// display. Against a real JournalWriter and the real rings.
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/journal/journal_drain.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/journal_fixtures.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::JournalRecord;
using stencil::control::SafeReason;
using namespace stencil::journal;
using namespace stencil::testing;

TEST_GROUP(JournalDrain){};

// The journal thread's side: a record that cannot be written asks the cycle to stop, and a full
// command ring does not lose that request.
TEST(JournalDrain, AWriteFailureReachesTheCycleEvenThroughAFullCommandRing) {
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

// Issue 22: each command the cycle took is a record of its own, before the record of its cycle, and
// the safe state says where it came from.
TEST(JournalDrain, TheDrainWritesEachCommandBeforeItsCyclesRecordAndTheSafeStateWithItsSource) {
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
