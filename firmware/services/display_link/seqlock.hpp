// A value shared between processes with one writer and any number of readers, none of whom ever
// waits for another: the writer never blocks (a reader that raced it just tries again), so the
// controller's threads publish to displays without a lock a display could hold.
//
// Lives inside the shared memory itself: no pointers, only the sequence and the value's words, each
// copied with a relaxed atomic access so that a torn read is detected, never undefined.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace stencil::display_link {

template <typename T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "only plain data crosses the process boundary");
  static_assert(std::atomic_ref<std::uint64_t>::is_always_lock_free, "a lock in shared memory could be held by a dead process");

 public:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

  // The one writer.
  void write(const T& value) {
    std::uint64_t words[kWords] = {};
    std::memcpy(words, &value, sizeof(T));
    const std::uint64_t sequence = sequence_.load(std::memory_order_relaxed);
    sequence_.store(sequence + 1, std::memory_order_relaxed);  // odd: being written
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) {
      std::atomic_ref<std::uint64_t>(words_[i]).store(words[i], std::memory_order_relaxed);
    }
    sequence_.store(sequence + 2, std::memory_order_release);
  }

  // A reader: false when the writer was part way through (try again); never a torn value.
  [[nodiscard]] bool try_read(T& out) const {
    const std::uint64_t before = sequence_.load(std::memory_order_acquire);
    if ((before & 1U) != 0) {
      return false;
    }
    std::uint64_t words[kWords];
    for (std::size_t i = 0; i < kWords; ++i) {
      words[i] = std::atomic_ref<std::uint64_t>(const_cast<std::uint64_t&>(words_[i])).load(std::memory_order_relaxed);
    }
    std::atomic_thread_fence(std::memory_order_acquire);
    if (sequence_.load(std::memory_order_relaxed) != before) {
      return false;
    }
    std::memcpy(&out, words, sizeof(T));
    return true;
  }

  // Up to `attempts` tries; false only if the writer kept it busy all that time.
  [[nodiscard]] bool read(T& out, int attempts = 10000) const {
    for (int i = 0; i < attempts; ++i) {
      if (try_read(out)) {
        return true;
      }
    }
    return false;
  }

  [[nodiscard]] std::uint64_t sequence() const { return sequence_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::uint64_t> sequence_{0};
  alignas(8) std::uint64_t words_[kWords] = {};
};

}  // namespace stencil::display_link
