// posix_journal_storage() (journal_storage.hpp; defined beside the writer): the file system's own
// write() and fsync(), one for the program, passing their results and errno through untouched so the
// writer can name a full disk or a bad file. Against a real file in /tmp and a closed descriptor.
// (The slow and full storage the writer's tests use is tests/fakes/fake_journal_storage.hpp.)
#include <cerrno>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "firmware/services/journal/journal_storage.hpp"
#include "tests/support/journal_fixtures.hpp"

#include <CppUTest/TestHarness.h>

using stencil::journal::JournalStorage;
using stencil::journal::posix_journal_storage;
using stencil::testing::TempJournal;

TEST_GROUP(JournalStorage){};

TEST(JournalStorage, ThePosixStorageIsOneForTheProgramAndWritesTheBytesToTheFile) {
  JournalStorage& storage = posix_journal_storage();
  CHECK(&storage == &posix_journal_storage());
  TempJournal file;
  const int fd = ::open(file.path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  CHECK(fd >= 0);
  const std::uint8_t bytes[5] = {'S', 'T', 0, 0xFF, 'J'};
  LONGS_EQUAL(5, storage.write(fd, bytes, sizeof bytes));
  LONGS_EQUAL(2, storage.write(fd, bytes, 2));
  LONGS_EQUAL(0, storage.fsync(fd));
  ::close(fd);
  const std::vector<std::uint8_t> want = {'S', 'T', 0, 0xFF, 'J', 'S', 'T'};
  CHECK(want == file.bytes());
}

// The writer turns errno into its error ("write failed: No space left on device"): it must be the
// system call's.
TEST(JournalStorage, ThePosixStorageFailsAsTheSystemCallsDoWithTheirErrno) {
  JournalStorage& storage = posix_journal_storage();
  const std::uint8_t byte = 1;
  errno = 0;
  LONGS_EQUAL(-1, storage.write(-1, &byte, 1));
  LONGS_EQUAL(EBADF, errno);
  errno = 0;
  LONGS_EQUAL(-1, storage.fsync(-1));
  LONGS_EQUAL(EBADF, errno);
  const int full = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  CHECK(full >= 0);
  errno = 0;
  LONGS_EQUAL(-1, storage.write(full, &byte, 1));
  LONGS_EQUAL(ENOSPC, errno);
  ::close(full);
}
