// The seqlock of the shared window (hal/pio_shared_memory/seqlock.hpp), alone on a plain block: a
// write moves the sequence by two and leaves it even; a read takes a whole write or nothing, never
// waits, and gives up after kSeqlockAttempts; a writer that died mid-write is resumed; and a reader
// racing a writer on another thread never takes a mixed block.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "hal/pio_shared_memory/seqlock.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace pio = hal::pio_shared_memory;

namespace {

pio::PoseWords pose_words(std::uint32_t k) {
  const auto value = static_cast<std::int32_t>(k);
  return pio::PoseWords{k, {value, -value, 2 * value}, {3 * value, -3 * value}, k ^ 0x5AU, k + 1U};
}

bool same(const pio::PoseWords& a, const pio::PoseWords& b) {
  return a.sample_counter == b.sample_counter && a.position_um[0] == b.position_um[0] &&
         a.position_um[1] == b.position_um[1] && a.position_um[2] == b.position_um[2] &&
         a.angles_urad[0] == b.angles_urad[0] && a.angles_urad[1] == b.angles_urad[1] &&
         a.status_bits == b.status_bits && a.device_heartbeat == b.device_heartbeat;
}

}  // namespace

// The window is a mapped memfd, as in use (a SharedWindow is cache-line aligned, which a test
// group's own allocation does not honour).
TEST_GROUP(Seqlock) {
  test::WindowPair windows = test::make_device_window();
  pio::SharedWindow& window = windows.device->window();
};

TEST(Seqlock, ABlockNeverWrittenReadsConsistentAsAllZeroWithSequenceZero) {
  pio::PoseWords words = pose_words(77);
  const pio::SeqlockRead read = pio::seqlock_read(window.pose, words);
  CHECK_TRUE(read.consistent);
  CHECK_EQUAL(0U, read.sequence);
  CHECK_EQUAL(0, read.retries);
  CHECK_TRUE(same(pio::PoseWords{}, words));
}

TEST(Seqlock, EachWriteMovesTheSequenceByTwoAndAReadTakesItWhole) {
  for (std::uint32_t k = 1; k <= 3; ++k) {
    pio::seqlock_write(window.pose, pose_words(k));
    CHECK_EQUAL(2U * k, window.pose.sequence);
    pio::PoseWords words{};
    const pio::SeqlockRead read = pio::seqlock_read(window.pose, words);
    CHECK_TRUE(read.consistent);
    CHECK_EQUAL(2U * k, read.sequence);
    CHECK_EQUAL(0, read.retries);
    CHECK_TRUE(same(pose_words(k), words));
  }
}

TEST(Seqlock, TheCommandBlockMovesEveryFieldToo) {
  const pio::CommandWords given{9U, {-5000, 0, 4999}, {200000, -1}, pio::kCommandEnableBit, 123456U};
  pio::seqlock_write(window.command, given);
  pio::CommandWords taken{};
  CHECK_TRUE(pio::seqlock_read(window.command, taken).consistent);
  CHECK_EQUAL(given.cycle_counter, taken.cycle_counter);
  for (int axis = 0; axis < 3; ++axis) CHECK_EQUAL(given.force_mn[axis], taken.force_mn[axis]);
  for (int axis = 0; axis < 2; ++axis) CHECK_EQUAL(given.torque_mnmm[axis], taken.torque_mnmm[axis]);
  CHECK_EQUAL(given.flags, taken.flags);
  CHECK_EQUAL(given.host_heartbeat, taken.host_heartbeat);
  CHECK_EQUAL(0U, window.pose.sequence);  // the other block is untouched
}

TEST(Seqlock, AWriteInProgressIsNeverReadAndTheReaderGivesUpWithoutWaiting) {
  pio::seqlock_write(window.pose, pose_words(1));
  window.pose.sequence += 1U;  // the writer is mid-write...
  window.pose.sample_counter = 2U;  // ...and has changed one field
  pio::PoseWords words = pose_words(99);
  const pio::SeqlockRead read = pio::seqlock_read(window.pose, words);
  CHECK_FALSE(read.consistent);
  CHECK_EQUAL(pio::kSeqlockAttempts, read.retries);
  CHECK_EQUAL(0U, read.sequence);
  CHECK_TRUE(same(pose_words(99), words));  // untouched
}

TEST(Seqlock, AWriterThatDiedMidWriteIsResumedToAnEvenSequence) {
  pio::seqlock_write(window.pose, pose_words(1));
  window.pose.sequence = 3U;  // odd: the last writer stopped mid-write
  pio::seqlock_write(window.pose, pose_words(2));
  CHECK_EQUAL(4U, window.pose.sequence);  // made odd (3 stays 3), then even: not 3 + 1 + 1
  pio::PoseWords words{};
  const pio::SeqlockRead read = pio::seqlock_read(window.pose, words);
  CHECK_TRUE(read.consistent);
  CHECK_TRUE(same(pose_words(2), words));
}

TEST(Seqlock, LoadAndStoreWordMoveOneWord) {
  std::int32_t word = 0;
  pio::store_word(word, -42);
  CHECK_EQUAL(-42, pio::load_word(word));
  CHECK_EQUAL(-42, word);
}

TEST(Seqlock, AReaderRacingAWriterOnAnotherThreadNeverTakesAMixedBlock) {
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (std::uint32_t k = 1; !stop.load(std::memory_order_relaxed); ++k) {
      pio::seqlock_write(window.pose, pose_words(k));
      if (k % 16U == 0U) std::this_thread::yield();  // let a reader on a shared core in now and then
    }
  });
  int whole = 0;
  int mixed = 0;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (whole < 20000 && std::chrono::steady_clock::now() < give_up) {
    pio::PoseWords words{};
    const pio::SeqlockRead read = pio::seqlock_read(window.pose, words);
    if (!read.consistent) continue;  // busy: nothing taken, which is the point
    ++whole;
    if (words.sample_counter != 0U && !same(pose_words(words.sample_counter), words)) ++mixed;
  }
  stop = true;
  writer.join();
  CHECK_EQUAL(0, mixed);
  CHECK_TRUE(whole > 100);  // enough whole reads to have looked at, even with one core shared
}
