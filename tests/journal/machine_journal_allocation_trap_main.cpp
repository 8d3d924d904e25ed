// The machine thread's side of the journal allocates nothing: MachineJournal::command() and written()
// (the ring push, the semaphore post, the published count) run with every heap entry point wrapped
// at link time, and the program fails if any is reached while armed. The records thread's side
// (encoding, the buffer, write()) may allocate and is run with the trap disarmed. A plain program
// rather than a CppUTest suite: CppUTest's own operator new would clash.
#include <cstdio>
#include <string>

#include <unistd.h>

#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/heap_trap.hpp"

int main() {
  using namespace stencil;
  char name[] = "/tmp/machine_journal_allocation_trap_XXXXXX";
  const int fd = mkstemp(name);
  if (fd < 0) {
    std::perror("machine_journal_allocation_trap: mkstemp");
    return 1;
  }
  ::close(fd);
  int failures = 0;
  {
    journal::JournalWriter writer;
    journal::JournalStart start;
    start.program = "machine_journal_allocation_trap";
    if (!writer.open(name, start)) {
      std::fprintf(stderr, "machine_journal_allocation_trap: %s\n", writer.error().c_str());
      return 1;
    }
    journal::MachineJournal machine(writer);
    control::MachineRecorder& recorder = machine;
    // Half the ring's capacity each round, drained (disarmed) between rounds, a few rounds.
    std::uint64_t update = 0;
    for (int round = 0; round < 8; ++round) {
      test::arm_heap_trap("machine_journal_allocation_trap");
      for (std::size_t i = 0; i < journal::JournalWriter::kMachineRingCapacity / 2; ++i) {
        const control::MachineCommandRecord record{update, static_cast<std::int64_t>(update), {1, 2, 3}, {0, 1, 2}, {1.0, 2.0, 3.0}};
        ++update;
        if (!recorder.command(record)) {
          ++failures;  // counted after disarming: printing allocates
        }
        static_cast<void>(machine.written());
      }
      test::disarm_heap_trap();
      if (!writer.write_machine_commands() || !machine.written()) {
        ++failures;
      }
    }
    if (writer.machine_records() != update) {
      ++failures;
    }
    static_cast<void>(writer.close());
  }
  std::remove(name);
  const unsigned long trapped = test::trapped_heap_calls();
  if (trapped != 0 || failures != 0) {
    std::fprintf(stderr, "machine_journal_allocation_trap: %lu heap calls on the machine thread's side, %d failures\n",
                 trapped, failures);
    return 1;
  }
  std::printf("machine_journal_allocation_trap: no heap call in command() and written()\n");
  return 0;
}
