// The seqlock that guards each block of the shared window: one writer, any number of readers,
// readers never wait and never use a block that a write was changing (see shared_window_layout.hpp).
#pragma once

#include <atomic>
#include <cstdint>

#include "hal/pio_shared_memory/shared_window_layout.hpp"

namespace stencil::hal::pio_shared_memory {

static_assert(std::atomic_ref<std::uint32_t>::is_always_lock_free);
static_assert(std::atomic_ref<std::int32_t>::is_always_lock_free);

// Every word of the window is accessed atomically (relaxed; the fences and the sequence word give the
// order), so a concurrent write is never a data race, only a torn value that the sequence rejects.
template <class Word>
[[nodiscard]] inline Word load_word(Word& word) {
  return std::atomic_ref<Word>(word).load(std::memory_order_relaxed);
}
template <class Word>
inline void store_word(Word& word, Word value) {
  std::atomic_ref<Word>(word).store(value, std::memory_order_relaxed);
}

inline void store_fields(PoseBlock& block, const PoseWords& words) {
  store_word(block.sample_counter, words.sample_counter);
  for (int axis = 0; axis < 3; ++axis) store_word(block.position_um[axis], words.position_um[axis]);
  for (int angle = 0; angle < 2; ++angle) store_word(block.angles_urad[angle], words.angles_urad[angle]);
  store_word(block.status_bits, words.status_bits);
  store_word(block.device_heartbeat, words.device_heartbeat);
}

inline void load_fields(PoseBlock& block, PoseWords& words) {
  words.sample_counter = load_word(block.sample_counter);
  for (int axis = 0; axis < 3; ++axis) words.position_um[axis] = load_word(block.position_um[axis]);
  for (int angle = 0; angle < 2; ++angle) words.angles_urad[angle] = load_word(block.angles_urad[angle]);
  words.status_bits = load_word(block.status_bits);
  words.device_heartbeat = load_word(block.device_heartbeat);
}

inline void store_fields(CommandBlock& block, const CommandWords& words) {
  store_word(block.cycle_counter, words.cycle_counter);
  for (int axis = 0; axis < 3; ++axis) store_word(block.force_mn[axis], words.force_mn[axis]);
  for (int axis = 0; axis < 2; ++axis) store_word(block.torque_mnmm[axis], words.torque_mnmm[axis]);
  store_word(block.flags, words.flags);
  store_word(block.host_heartbeat, words.host_heartbeat);
}

inline void load_fields(CommandBlock& block, CommandWords& words) {
  words.cycle_counter = load_word(block.cycle_counter);
  for (int axis = 0; axis < 3; ++axis) words.force_mn[axis] = load_word(block.force_mn[axis]);
  for (int axis = 0; axis < 2; ++axis) words.torque_mnmm[axis] = load_word(block.torque_mnmm[axis]);
  words.flags = load_word(block.flags);
  words.host_heartbeat = load_word(block.host_heartbeat);
}

// One write by the block's only writer. A sequence left odd by a writer that died mid-write is
// resumed (made odd, then even), not doubled back to even by a single step. Real-time safe.
template <class Block, class Words>
inline void seqlock_write(Block& block, const Words& words) {
  std::atomic_ref<std::uint32_t> sequence(block.sequence);
  const std::uint32_t writing = sequence.load(std::memory_order_relaxed) | 1U;
  sequence.store(writing, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);  // the odd sequence is visible before any field
  store_fields(block, words);
  sequence.store(writing + 1U, std::memory_order_release);  // every field is visible before the even one
}

struct SeqlockRead {
  bool consistent;          // `words` came from one write (possibly the zero block never written)
  int retries;              // attempts that met a write in progress
  std::uint32_t sequence;   // the even sequence the words belong to (0: never written)
};

// At most kSeqlockAttempts attempts, never a wait; `words` is written only when consistent.
template <class Block, class Words>
[[nodiscard]] inline SeqlockRead seqlock_read(Block& block, Words& words) {
  std::atomic_ref<std::uint32_t> sequence(block.sequence);
  for (int attempt = 0; attempt < kSeqlockAttempts; ++attempt) {
    const std::uint32_t before = sequence.load(std::memory_order_acquire);
    if ((before & 1U) != 0U) continue;  // a write is in progress
    Words candidate{};
    load_fields(block, candidate);
    std::atomic_thread_fence(std::memory_order_acquire);  // the fields are read before the second look
    if (sequence.load(std::memory_order_relaxed) == before) {
      words = candidate;
      return {true, attempt, before};
    }
  }
  return {false, kSeqlockAttempts, 0};
}

}  // namespace stencil::hal::pio_shared_memory
