// JournalWriter: the journal file's one owner, on a thread that is not the cycle's (it writes and
// fsyncs, which block). It is fed the records the cycle left in its journal ring, buffers them and
// syncs them to the disk at least once a second and at once on a safe-state event.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/control/cycle_messages.hpp"
#include "firmware/journal/journal_format.hpp"

namespace stencil::journal {

struct JournalStart {
  std::uint32_t tables_crc32 = 0;
  std::uint32_t triangle_count = 0;
  std::int64_t unix_time_ns = 0;
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

  // One cycle's record. The first record in the safe state also appends a SafeState record and
  // syncs at once. False once anything failed to reach the file (error() says what; nothing is
  // written after that).
  [[nodiscard]] bool append(const control::JournalRecord& record);

  // Writes out and fsyncs when a second has passed since the last sync (now_ns: any monotonic clock).
  [[nodiscard]] bool sync_if_due(std::int64_t now_ns);
  // Writes out and fsyncs now.
  [[nodiscard]] bool sync();
  // Syncs and closes; the destructor does the same, ignoring failure.
  [[nodiscard]] bool close();

  [[nodiscard]] bool is_open() const { return fd_ >= 0; }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::uint64_t cycle_records() const { return cycle_records_; }
  [[nodiscard]] std::uint64_t syncs() const { return syncs_; }
  [[nodiscard]] std::uint64_t bytes_written() const { return bytes_written_; }

 private:
  void add_record(RecordType type, const std::uint8_t* payload, std::uint32_t length);
  [[nodiscard]] bool write_out();
  [[nodiscard]] bool fail(const std::string& what, int error_number);

  int fd_ = -1;
  std::string path_;
  std::string error_;
  std::vector<std::uint8_t> buffer_;
  bool failed_ = false;
  bool in_safe_state_ = false;
  std::int64_t last_sync_ns_ = 0;
  bool synced_once_ = false;
  std::uint64_t cycle_records_ = 0;
  std::uint64_t syncs_ = 0;
  std::uint64_t bytes_written_ = 0;
};

}  // namespace stencil::journal
