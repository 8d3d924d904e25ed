// A fixed-capacity set of triangle ids (the touched triangles), one bit each, updated in place.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/tables/table_format.hpp"

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
    }
    return true;
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
};

}  // namespace stencil::engine
