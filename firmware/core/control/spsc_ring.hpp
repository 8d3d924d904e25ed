// SpscRing: a fixed-capacity single-producer/single-consumer queue between the 1 kHz cycle and the
// threads around it (machine, telemetry, journal, commands). Lock-free and allocation-free.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace stencil::control {

// Capacity is in the type (a power of two). push() by one thread, pop() by one other: each index
// is written by one side only, and read by the other with acquire/release, so an element is fully
// written before the consumer can see it. Neither side ever waits: a full ring refuses the push
// (the producer counts it and decides what that means), an empty one refuses the pop.
template <typename T, std::size_t Capacity>
class SpscRing {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity must be a power of two");
  static_assert(std::is_trivially_copyable_v<T>, "elements are copied in and out as plain data");

 public:
  SpscRing() = default;
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer side. False (nothing written) when full. Real-time safe.
  [[nodiscard]] bool push(const T& value) {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_.load(std::memory_order_acquire) >= Capacity) {
      return false;
    }
    slots_[tail & (Capacity - 1)] = value;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  // Consumer side. False (out untouched) when empty. Real-time safe.
  [[nodiscard]] bool pop(T& out) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) {
      return false;
    }
    out = slots_[head & (Capacity - 1)];
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  // Either side: how many elements are waiting (a snapshot; exact only for the side that is not
  // moving its index at the time).
  [[nodiscard]] std::size_t size() const {
    return static_cast<std::size_t>(tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire));
  }
  [[nodiscard]] static constexpr std::size_t capacity() { return Capacity; }

 private:
  // The two indices on their own cache lines, so the two threads do not fight over one line.
  alignas(64) std::atomic<std::uint64_t> head_{0};  // next to pop; written by the consumer only
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // next to push; written by the producer only
  alignas(64) std::array<T, Capacity> slots_{};
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "the ring's indices must be lock-free");
};

}  // namespace stencil::control
