// A fixed-capacity set of triangle ids (the touched triangles), one bit each, updated in place.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/core/tables/table_format.hpp"

namespace stencil::engine {

// Capacity in the type: kMaxTableTriangles bits (256 KiB). Meant for static storage. Unlike
// std::bitset it never throws: an id beyond capacity is refused and counted.
class TriangleSet {
 public:
  static constexpr std::size_t kCapacity = tables::kMaxTableTriangles;

  // Adds the id; false (and the refusal counted) when it is beyond capacity. Real-time safe.
  bool insert(std::uint32_t id) {
    if (id >= kCapacity) {
      ++refused_;
      return false;
    }
    std::uint64_t& word = words_[id / 64];
    const std::uint64_t bit = std::uint64_t{1} << (id % 64);
    if ((word & bit) == 0) {
      word |= bit;
      ++count_;
      if (observer_ != nullptr) {
        observer_(observer_context_, id);
      }
    }
    return true;
  }

  // Who hears of each id added anew (a display's mirror of the set, for its deltas); nobody by
  // default. The observer runs inside insert(), so on the cycle's set it must be real-time safe.
  using Observer = void (*)(void* context, std::uint32_t id);
  void observe(Observer observer, void* context) {
    observer_ = observer;
    observer_context_ = context;
  }

  [[nodiscard]] bool contains(std::uint32_t id) const {
    return id < kCapacity && (words_[id / 64] & (std::uint64_t{1} << (id % 64))) != 0;
  }

  [[nodiscard]] std::size_t count() const { return count_; }
  [[nodiscard]] std::size_t refused() const { return refused_; }

  void clear() {
    words_.fill(0);
    count_ = 0;
    refused_ = 0;
  }

 private:
  std::array<std::uint64_t, kCapacity / 64> words_{};
  std::size_t count_ = 0;
  std::size_t refused_ = 0;
  Observer observer_ = nullptr;
  void* observer_context_ = nullptr;
};

}  // namespace stencil::engine
