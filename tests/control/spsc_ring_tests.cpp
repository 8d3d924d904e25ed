// The ring between the cycle and its threads: order, full and empty refusals, and two threads.
#include <cstdint>
#include <thread>

#include "firmware/core/control/spsc_ring.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::SpscRing;

TEST_GROUP(SpscRing){};

TEST(SpscRing, GivesBackWhatWasPushedInOrderAndRefusesWhenEmpty) {
  SpscRing<int, 8> ring;
  int out = -1;
  CHECK_FALSE(ring.pop(out));
  LONGS_EQUAL(-1, out);
  for (int i = 0; i < 5; ++i) {
    CHECK(ring.push(i));
  }
  LONGS_EQUAL(5, ring.size());
  for (int i = 0; i < 5; ++i) {
    CHECK(ring.pop(out));
    LONGS_EQUAL(i, out);
  }
  CHECK_FALSE(ring.pop(out));
}

TEST(SpscRing, AFullRingRefusesThePushAndKeepsWhatItHeld) {
  SpscRing<int, 4> ring;
  for (int i = 0; i < 4; ++i) {
    CHECK(ring.push(10 + i));
  }
  CHECK_FALSE(ring.push(99));
  LONGS_EQUAL(4, ring.size());
  int out = 0;
  CHECK(ring.pop(out));
  LONGS_EQUAL(10, out);
  CHECK(ring.push(14));  // room again
  for (int expected = 11; expected <= 14; ++expected) {
    CHECK(ring.pop(out));
    LONGS_EQUAL(expected, out);
  }
}

TEST(SpscRing, WrapsAroundItsStorageManyTimes) {
  SpscRing<std::uint32_t, 4> ring;
  std::uint32_t out = 0;
  for (std::uint32_t i = 0; i < 1000; ++i) {
    CHECK(ring.push(i));
    CHECK(ring.push(i + 100000));
    CHECK(ring.pop(out));
    LONGS_EQUAL(i, out);
    CHECK(ring.pop(out));
    LONGS_EQUAL(i + 100000, out);
  }
}

TEST(SpscRing, TwoThreadsPassAMillionRecordsWithNoneLostTornOrReordered) {
  struct Record {
    std::uint64_t sequence;
    std::uint64_t check;  // a function of the sequence: a torn record would not match
  };
  static SpscRing<Record, 64> ring;
  constexpr std::uint64_t kRecords = 1'000'000;
  // Each side yields when it cannot go on: spinning instead, with the other core busy (CI runs two
  // suites at once), the two threads took turns a time slice at a time, 64 records per turn, and
  // this test took 92 s under ASan against 7 s alone.
  std::thread producer([] {
    for (std::uint64_t i = 0; i < kRecords;) {
      if (ring.push({i, i * 0x9E3779B97F4A7C15ULL})) {
        ++i;
      } else {
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 0;
  std::uint64_t bad = 0;
  while (expected < kRecords) {
    Record record{};
    if (ring.pop(record)) {
      bad += (record.sequence != expected || record.check != expected * 0x9E3779B97F4A7C15ULL) ? 1 : 0;
      ++expected;
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();
  LONGS_EQUAL(0, bad);
  LONGS_EQUAL(0, ring.size());
}
