// JournalStorage: the journal writer's one way to its file, write() and fsync(), as an interface: the
// writer uses the file system's own (posix_journal_storage()); a test gives it storage that is slow
// or full, as an SD card that stalls or a disk that fills.
#pragma once

#include <cstddef>
#include <cstdint>

#include <sys/types.h>

namespace stencil::journal {

// Called by whichever thread writes the journal out, under the writer's lock (never by the machine
// thread, never by the cycle): both may block for as long as the storage takes.
class JournalStorage {
 public:
  JournalStorage() = default;
  JournalStorage(const JournalStorage&) = delete;
  JournalStorage& operator=(const JournalStorage&) = delete;

  // As write(2): the bytes taken (possibly fewer than size), or -1 with errno set.
  virtual ssize_t write(int fd, const std::uint8_t* data, std::size_t size) = 0;
  // As fsync(2): 0 once the file's data is on the disk, or -1 with errno set.
  virtual int fsync(int fd) = 0;

 protected:
  ~JournalStorage() = default;  // not owned through this interface
};

// The file system's: ::write and ::fsync. One for the program, stateless.
[[nodiscard]] JournalStorage& posix_journal_storage();

}  // namespace stencil::journal
