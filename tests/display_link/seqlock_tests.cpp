// Seqlock (seqlock.hpp), the feed's one-writer cells in shared memory: what is written reads back
// whole, whatever the type's size; each write moves the sequence on by two; a reader finding a write
// in progress (or one left half done by a writer that died) gets false and its value untouched, never
// a torn value; and a reader racing a real writer thread sees whole values in order.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <memory>
#include <new>
#include <thread>

#include "firmware/services/display_link/seqlock.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using stencil::display_link::Seqlock;

namespace {

// Not a multiple of 8 bytes: the last word is only partly the value's.
struct Odd {
  std::int32_t position_um[3];
  std::uint16_t status;
  char name[5];
};
static_assert(sizeof(Odd) % 8 != 0);

}  // namespace

TEST_GROUP(Seqlock) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(Seqlock, WhatIsWrittenReadsBackWholeAndEachWriteMovesTheSequenceOnByTwo) {
  Seqlock<Odd> cell;
  LONGS_EQUAL((sizeof(Odd) + 7) / 8, Seqlock<Odd>::kWords);
  CHECK_EQUAL(0U, cell.sequence());
  Odd out{{9, 9, 9}, 9, "9999"};
  CHECK_TRUE(cell.try_read(out));  // never written: zeros, and that is a whole value
  LONGS_EQUAL(0, out.position_um[0]);
  LONGS_EQUAL(0, out.status);
  const Odd first{{1500, -2250, 1}, 0xBEEF, "abcd"};
  cell.write(first);
  CHECK_EQUAL(2U, cell.sequence());
  CHECK_TRUE(cell.read(out));
  LONGS_EQUAL(1500, out.position_um[0]);
  LONGS_EQUAL(-2250, out.position_um[1]);
  LONGS_EQUAL(1, out.position_um[2]);
  LONGS_EQUAL(0xBEEF, out.status);
  STRCMP_EQUAL("abcd", out.name);
  const Odd second{{3, 4, 5}, 7, "wxyz"};
  cell.write(second);
  CHECK_EQUAL(4U, cell.sequence());
  CHECK_TRUE(cell.try_read(out));
  LONGS_EQUAL(5, out.position_um[2]);
  STRCMP_EQUAL("wxyz", out.name);
}

// The cell lives in shared memory, its sequence odd while the writer is part way through (for good,
// if the writer died there). Readers give up (false, their value as it was) rather than take the
// half-written words, and read again once the sequence is even.
TEST(Seqlock, AWriteInProgressIsNeverReadAndTheReadersValueIsLeftAsItWas) {
  alignas(Seqlock<Odd>) unsigned char shared[sizeof(Seqlock<Odd>)];
  // CppUTest's leak detector defines `new` as a macro, which placement new cannot take.
#pragma push_macro("new")
#undef new
  auto* cell = new (shared) Seqlock<Odd>();
#pragma pop_macro("new")
  const Odd written{{1, 2, 3}, 1, "one"};
  cell->write(written);
  std::uint64_t sequence = 0;
  std::memcpy(&sequence, shared, sizeof sequence);  // the sequence is the cell's first word
  CHECK_EQUAL(cell->sequence(), sequence);
  sequence += 1;  // odd: being written
  std::memcpy(shared, &sequence, sizeof sequence);
  Odd out{{7, 7, 7}, 7, "keep"};
  CHECK_FALSE(cell->try_read(out));
  CHECK_FALSE(cell->read(out, 50));
  LONGS_EQUAL(7, out.position_um[0]);
  STRCMP_EQUAL("keep", out.name);
  // The write finishes (even again, two on): read whole.
  sequence += 1;
  std::memcpy(shared, &sequence, sizeof sequence);
  CHECK_TRUE(cell->read(out));
  STRCMP_EQUAL("one", out.name);
  LONGS_EQUAL(3, out.position_um[2]);
  cell->~Seqlock<Odd>();
}

// A reader racing the writer gets whole values only: each value written has every word equal.
TEST(Seqlock, AReaderRacingTheWriterNeverSeesATornValue) {
  struct Wide {
    std::uint64_t words[64];
  };
  auto cell = std::make_unique<Seqlock<Wide>>();
  std::atomic<bool> done{false};
  std::thread writer([&] {
    Wide value{};
    for (std::uint64_t n = 1; n < 200000; ++n) {
      std::fill(std::begin(value.words), std::end(value.words), n);
      cell->write(value);
    }
    done = true;
  });
  std::uint64_t reads = 0, torn = 0, last = 0;
  bool monotonic = true;
  while (!done.load()) {
    Wide seen{};
    if (cell->try_read(seen)) {
      ++reads;
      for (const std::uint64_t word : seen.words) {
        torn += word != seen.words[0] ? 1 : 0;
      }
      monotonic = monotonic && seen.words[0] >= last;
      last = seen.words[0];
    }
  }
  writer.join();
  CHECK(reads > 0U);
  CHECK_EQUAL(0U, torn);
  CHECK(monotonic);
}
