// JournalWriter: the journal file's one owner, fed by threads that are not the cycle's (it writes and
// fsyncs, which block, and it locks): the records thread gives it the records the cycle left in its
// journal ring, which it buffers and syncs to the disk at least once a second and at once on a
// safe-state event; the machine thread gives it the homing and each target before sending it, which
// it writes through at once (with everything buffered before), so a crash of the program cannot
// lose a command the mill was sent.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "firmware/control/cycle_messages.hpp"
#include "firmware/control/machine_record.hpp"
#include "firmware/journal/journal_format.hpp"

namespace stencil::journal {

struct JournalStart {
  std::uint32_t tables_crc32 = 0;
  std::uint32_t triangle_count = 0;
  std::int64_t unix_time_ns = 0;
  std::string program;
  std::string job;  // at most 1024 bytes: the job's description, as the program gives it
};

// A resumed job's next segment.
struct JournalResume {
  std::uint32_t segment = 0;  // 1 for the first resume
  std::int64_t unix_time_ns = 0;
  double script_s = 0.0;      // the simulated operator: its script carries on from here ...
  double approach_s = 0.0;    // ... after this long on the way back to the cut (0, 0: a person)
  std::string program;
};

class JournalWriter {
 public:
  JournalWriter() = default;
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;
  ~JournalWriter();

  // Creates (or truncates) `path`, writes the file header and the Start record and syncs them.
  // False with error() naming the file and the reason.
  [[nodiscard]] bool open(const std::string& path, const JournalStart& start);

  // Opens a journal to carry on with it: cuts it to `good_bytes` (what its reader found whole; a
  // torn tail goes), appends the Resume record and syncs. False with error() as for open().
  [[nodiscard]] bool open_to_resume(const std::string& path, std::size_t good_bytes, const JournalResume& resume);

  // From the machine thread, written through at once: the machine homed; a target it will send.
  [[nodiscard]] bool append_homed(std::int64_t time_ns);
  [[nodiscard]] bool append_machine_command(const control::MachineCommandRecord& record);

  // One cycle's record. The first record in the safe state also appends a SafeState record and
  // syncs at once. False once anything failed to reach the file (error() says what; nothing is
  // written after that).
  [[nodiscard]] bool append(const control::JournalRecord& record);

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
  [[nodiscard]] std::uint64_t syncs() const { return syncs_; }
  [[nodiscard]] std::uint64_t bytes_written() const { return bytes_written_; }

 private:
  [[nodiscard]] bool sync_locked(std::unique_lock<std::mutex>& lock);
  void add_record(RecordType type, const std::uint8_t* payload, std::uint32_t length);
  [[nodiscard]] bool write_out();
  [[nodiscard]] bool fail(const std::string& what, int error_number);

  std::mutex mutex_;  // the records thread and the machine thread both write
  int fd_ = -1;
  std::string path_;
  std::string error_;
  std::vector<std::uint8_t> buffer_;
  bool failed_ = false;
  bool in_safe_state_ = false;
  std::int64_t last_sync_ns_ = 0;
  bool synced_once_ = false;
  std::uint64_t cycle_records_ = 0;
  std::uint64_t machine_records_ = 0;
  std::uint64_t syncs_ = 0;
  std::uint64_t bytes_written_ = 0;
};

// The machine side's recorder: the journal, when there is one.
class MachineJournal final : public control::MachineRecorder {
 public:
  explicit MachineJournal(JournalWriter& writer) : writer_(writer) {}
  [[nodiscard]] bool homed(std::int64_t time_ns) override { return writer_.append_homed(time_ns); }
  [[nodiscard]] bool command(const control::MachineCommandRecord& record) override {
    return writer_.append_machine_command(record);
  }

 private:
  JournalWriter& writer_;
};

}  // namespace stencil::journal
