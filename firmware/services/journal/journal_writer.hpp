// JournalWriter: the journal file's one owner, fed by two threads that are not the cycle's (it
// writes and fsyncs, which block, and it locks). The records thread gives it the records the cycle
// left in its journal ring, which it buffers and syncs to the disk at least once a second and at
// once on a safe-state event. The machine thread gives it the homing (at start, written through
// at once) and each target before sending it.
//
// Issue 18, item 10: the records thread holds the writer's lock across write(), and storage that
// stalls makes that long; a machine thread that took the same lock to write its target missed its
// update's deadline, which is a fault. So the machine thread never takes the lock: it puts the
// target into a fixed-size ring (append_machine_command, lock-free, allocation-free), which wakes
// the records thread; the records thread writes the ring's targets through at once, with everything
// buffered before them, and only then publishes how many are in the file
// (machine_commands_written). The machine side sends a target only once it is in the file (see
// control::MachineRecorder): nothing that was machined is lost from the record by a crash of the
// program, as before; what slow storage costs now is time (the mill holds, its updates are not
// late), not a fault, until it has held for MachineSide's bound. A crash of the host still loses
// what was not synced (at most a second), as before.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <semaphore.h>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/machine_record.hpp"
#include "firmware/core/control/spsc_ring.hpp"
#include "firmware/services/journal/cycle_codec.hpp"
#include "firmware/services/journal/journal_bytes.hpp"
#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/journal/journal_storage.hpp"

namespace stencil::journal {

struct JournalStart {
  std::uint32_t tables_crc32 = 0;
  std::uint32_t triangle_count = 0;
  std::int64_t unix_time_ns = 0;
  std::string program;
  std::string job;  // at most 1024 bytes: the job's description, as the program gives it
  std::string provenance;  // what made the run (report::provenance_line); "": no Provenance record
};

// A resumed job's next segment.
struct JournalResume {
  std::uint32_t segment = 0;  // 1 for the first resume
  std::int64_t unix_time_ns = 0;
  double script_s = 0.0;      // the simulated operator: its script carries on from here ...
  double approach_s = 0.0;    // ... after this long on the way back to the cut (0, 0: a person)
  std::string program;
  std::string provenance;     // as JournalStart's (not written into a version 3 journal carried on)
};

class JournalWriter {
 public:
  // Targets the machine thread may have queued that the records thread has not written yet. The
  // machine side queues one and holds it until it is written, so one slot is in use at a time; a
  // full ring (a machine side that did not wait) refuses the target, which is then not sent: a
  // journal fault, counted, never a silent drop. 32: a second of updates at 30 Hz, so even a
  // machine side that sent without waiting could leave no more unwritten than a crash of the host
  // loses anyway (the file is synced once a second).
  static constexpr std::size_t kMachineRingCapacity = 32;

  // The file system's storage; a test passes its own (slow, full).
  JournalWriter() : JournalWriter(posix_journal_storage()) {}
  explicit JournalWriter(JournalStorage& storage);
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;
  ~JournalWriter();

  // Creates (or truncates) `path`, writes the file header and the Start record and syncs them.
  // False with error() naming the file and the reason.
  [[nodiscard]] bool open(const std::string& path, const JournalStart& start);

  // Opens a journal to carry on with it: cuts it to `good_bytes` (what its reader found whole; a
  // torn tail goes), appends the Resume record and syncs. False with error() as for open().
  [[nodiscard]] bool open_to_resume(const std::string& path, std::size_t good_bytes, const JournalResume& resume);

  // Init, before the machine thread runs (MachineSide::start): the machine homed, written through
  // at once; blocks on the file. Never from the machine thread's updates.
  [[nodiscard]] bool append_homed(std::int64_t time_ns);

  // The machine thread (one thread), at each update: queues a target it will send once written.
  // Real-time safe: no lock, no allocation, no system call but a semaphore post (it wakes the
  // records thread). False (nothing queued) when the journal is not open or has failed, or the ring
  // is full (counted in machine_commands_refused()).
  [[nodiscard]] bool append_machine_command(const control::MachineCommandRecord& record);
  // The machine thread: every target it queued is in the file (written, not yet synced), so the
  // newest may be sent. Real-time safe. Stays false for a target queued after the journal failed.
  [[nodiscard]] bool machine_commands_written() const;

  // The records thread (or whichever one thread writes the cycle's records): writes every queued
  // target out at once, with everything buffered before it, then publishes them as written. False
  // once anything failed to reach the file. append(), append_end() and the syncs do this first too,
  // so a target is never behind a record that came after it.
  [[nodiscard]] bool write_machine_commands();
  // The records thread, between its looks: returns once the machine thread has queued a target (so
  // it is written before the machine side's next update, which sends it) or after `most`.
  void wait_for_machine_commands(std::chrono::nanoseconds most);

  // One cycle's record. The first record in the safe state also appends a SafeState record and
  // syncs at once. False once anything failed to reach the file (error() says what; nothing is
  // written after that).
  [[nodiscard]] bool append(const control::JournalRecord& record);

  // A command the cycle took, before the record of the cycle that took it (the records thread keeps
  // that order: journal::JournalDrain). False as for append().
  [[nodiscard]] bool append_command(const control::CommandEvent& event);

  // The run ends in order: its End record, synced (call once, after the last cycle's record).
  [[nodiscard]] bool append_end(std::uint64_t cycles, control::SafeReason reason);

  // Writes out and fsyncs when a second has passed since the last sync (now_ns: any monotonic clock).
  [[nodiscard]] bool sync_if_due(std::int64_t now_ns);
  // Writes out and fsyncs now.
  [[nodiscard]] bool sync();
  // Syncs and closes; the destructor does the same, ignoring failure.
  [[nodiscard]] bool close();

  // Read these once the threads that feed the writer are done.
  [[nodiscard]] bool is_open() const { return fd_ >= 0; }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::uint64_t cycle_records() const { return cycle_records_; }
  [[nodiscard]] std::uint64_t machine_records() const { return machine_records_; }
  [[nodiscard]] std::uint64_t command_records() const { return command_records_; }
  [[nodiscard]] std::uint64_t machine_commands_refused() const { return machine_refused_.load(); }
  [[nodiscard]] std::uint64_t syncs() const { return syncs_; }
  [[nodiscard]] std::uint64_t bytes_written() const { return bytes_written_; }

 private:
  [[nodiscard]] bool sync_locked(std::unique_lock<std::mutex>& lock);
  [[nodiscard]] bool write_machine_commands_locked();
  void add_record(RecordType type, const std::uint8_t* payload, std::uint32_t length);
  void end_cycles();  // the cycles encoded so far into a Cycles record, before anything else
  void add_provenance(const std::string& text);  // a Provenance record, when there is a text
  [[nodiscard]] bool write_out();
  [[nodiscard]] bool fail(const std::string& what, int error_number);

  JournalStorage& storage_;
  // Held by the thread that writes the file (the records thread; the main thread to open, to record
  // the homing before the machine thread runs, and to close), across write(): never by the machine
  // thread's updates, never by the cycle.
  std::mutex mutex_;
  // The machine thread's targets on their way to the file: it is the ring's one producer; the
  // consumer pops under mutex_ (so whichever thread writes, one at a time).
  control::SpscRing<control::MachineCommandRecord, kMachineRingCapacity> machine_ring_;
  std::uint64_t machine_queued_ = 0;                 // targets queued: the machine thread's own count
  std::uint64_t machine_taken_ = 0;                  // targets taken off the ring: under mutex_
  std::atomic<std::uint64_t> machine_written_{0};    // of those, in the file: published after write()
  std::atomic<std::uint64_t> machine_refused_{0};    // refused by a full ring
  std::atomic<bool> accepting_{false};               // open and not failed, for the machine thread
  sem_t machine_queued_signal_{};                    // posted per target queued: wakes the records thread
  int fd_ = -1;
  std::string path_;
  std::string error_;
  std::vector<std::uint8_t> buffer_;
  CycleEncoder encoder_;
  ByteWriter cycles_;  // the open Cycles record's payload
  std::uint32_t cycles_in_record_ = 0;
  bool failed_ = false;
  bool in_safe_state_ = false;
  std::int64_t last_sync_ns_ = 0;
  bool synced_once_ = false;
  std::uint64_t cycle_records_ = 0;
  std::uint64_t machine_records_ = 0;
  std::uint64_t command_records_ = 0;
  std::uint64_t syncs_ = 0;
  std::uint64_t bytes_written_ = 0;
};

// The machine side's recorder on the rig and in real-time runs (the machine thread apart from the
// records thread): each target is queued for the records thread and sent once written().
class MachineJournal final : public control::MachineRecorder {
 public:
  explicit MachineJournal(JournalWriter& writer) : writer_(writer) {}
  [[nodiscard]] bool homed(std::int64_t time_ns) override { return writer_.append_homed(time_ns); }
  [[nodiscard]] bool command(const control::MachineCommandRecord& record) override {
    return writer_.append_machine_command(record);
  }
  // The machine thread, before sending the newest target it queued: is it in the file yet?
  [[nodiscard]] bool written() const override { return writer_.machine_commands_written(); }

 private:
  JournalWriter& writer_;
};

// The machine side's recorder for a loop that runs the machine update and the records on one thread
// (stencil-sim --fast, on the virtual clock): the caller writes each target through itself, at once,
// so it is written() before command() returns and the target goes out in the same update, as it
// always did. No other thread may feed the writer then: with one thread there is no lock to wait on.
class InlineMachineJournal final : public control::MachineRecorder {
 public:
  explicit InlineMachineJournal(JournalWriter& writer) : writer_(writer) {}
  [[nodiscard]] bool homed(std::int64_t time_ns) override { return writer_.append_homed(time_ns); }
  [[nodiscard]] bool command(const control::MachineCommandRecord& record) override {
    return writer_.append_machine_command(record) && writer_.write_machine_commands();
  }
  [[nodiscard]] bool written() const override { return writer_.machine_commands_written(); }

 private:
  JournalWriter& writer_;
};

}  // namespace stencil::journal
