// The touched set (stencil/triangle_set.hpp): one bit per triangle id, each id counted once, the
// observer told of each id added anew, and an id beyond the capacity refused and counted instead
// of written anywhere.
#include <cstdint>
#include <vector>

#include "firmware/core/stencil/triangle_set.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::engine;

namespace {

TriangleSet the_set;  // 256 KiB: static storage, as on the rig

void record(void* context, std::uint32_t id) { static_cast<std::vector<std::uint32_t>*>(context)->push_back(id); }

}  // namespace

TEST_GROUP(TriangleSet) {
  TriangleSet& set = the_set;
  void setup() override {
    set.observe(nullptr, nullptr);
    set.clear();
  }
};

TEST(TriangleSet, AnIdIsCountedOnceHoweverOftenItIsInserted) {
  CHECK(set.insert(7));
  CHECK(set.insert(7));
  CHECK(set.insert(64));  // the next word
  CHECK(set.insert(63));  // the last bit of the first
  LONGS_EQUAL(3, set.count());
  CHECK(set.contains(7));
  CHECK(set.contains(63));
  CHECK(set.contains(64));
  CHECK_FALSE(set.contains(6));
  CHECK_FALSE(set.contains(65));
}

TEST(TriangleSet, TheLastIdFitsAndOneBeyondIsRefusedAndCountedNotWritten) {
  const auto last = static_cast<std::uint32_t>(TriangleSet::kCapacity - 1);
  CHECK(set.insert(last));
  CHECK(set.contains(last));
  CHECK_FALSE(set.insert(last + 1));
  CHECK_FALSE(set.insert(0xFFFFFFFFU));
  CHECK_FALSE(set.contains(last + 1));
  LONGS_EQUAL(1, set.count());
  LONGS_EQUAL(2, set.refused());
}

TEST(TriangleSet, TheObserverHearsOfEachIdOnlyWhenItIsNew) {
  std::vector<std::uint32_t> heard;
  set.observe(record, &heard);
  CHECK(set.insert(5));
  CHECK(set.insert(5));
  CHECK(set.insert(1000));
  CHECK_FALSE(set.insert(static_cast<std::uint32_t>(TriangleSet::kCapacity)));  // refused: not heard
  LONGS_EQUAL(2, heard.size());
  LONGS_EQUAL(5, heard[0]);
  LONGS_EQUAL(1000, heard[1]);
}

TEST(TriangleSet, ClearEmptiesTheSetAndItsRefusals) {
  CHECK(set.insert(3));
  CHECK_FALSE(set.insert(static_cast<std::uint32_t>(TriangleSet::kCapacity)));
  set.clear();
  LONGS_EQUAL(0, set.count());
  LONGS_EQUAL(0, set.refused());
  CHECK_FALSE(set.contains(3));
  CHECK(set.insert(3));  // new again
  LONGS_EQUAL(1, set.count());
}
