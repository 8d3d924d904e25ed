// FakeJournalStorage: the journal's file through the real write(2) and fsync(2), made slow or full on
// demand: each write can take a set time first (storage that stalls, with the writer's lock held),
// and writes can be refused with an errno (a full disk). Counts the writes begun, so a test knows
// when another thread is inside one.
#pragma once

#include <atomic>
#include <cerrno>
#include <chrono>
#include <thread>

#include <unistd.h>

#include "firmware/services/journal/journal_storage.hpp"

namespace stencil::test {

class FakeJournalStorage final : public journal::JournalStorage {
 public:
  // Every write from now on takes this long before its bytes go to the file (0: as fast as the file).
  void make_writes_take(std::chrono::nanoseconds delay) { delay_ns_.store(delay.count()); }
  // Every write from now on fails with this errno (0: none fail).
  void fail_writes_with(int error_number) { fail_errno_.store(error_number); }

  [[nodiscard]] int writes_begun() const { return writes_begun_.load(); }
  [[nodiscard]] int writes_done() const { return writes_done_.load(); }
  [[nodiscard]] int syncs() const { return syncs_.load(); }

  ssize_t write(int fd, const std::uint8_t* data, std::size_t size) override {
    writes_begun_.fetch_add(1);
    const auto delay = std::chrono::nanoseconds(delay_ns_.load());
    if (delay.count() > 0) {
      std::this_thread::sleep_for(delay);
    }
    const int error_number = fail_errno_.load();
    ssize_t written = -1;
    if (error_number != 0) {
      errno = error_number;
    } else {
      written = ::write(fd, data, size);
    }
    writes_done_.fetch_add(1);
    return written;
  }

  int fsync(int fd) override {
    syncs_.fetch_add(1);
    return ::fsync(fd);
  }

 private:
  std::atomic<long long> delay_ns_{0};
  std::atomic<int> fail_errno_{0};
  std::atomic<int> writes_begun_{0};
  std::atomic<int> writes_done_{0};
  std::atomic<int> syncs_{0};
};

}  // namespace stencil::test
