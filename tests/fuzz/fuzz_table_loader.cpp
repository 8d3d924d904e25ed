// libFuzzer target: the table loader refuses any malformed bytes without reading outside them.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <memory>
#include <new>
#include <span>

#include "firmware/core/tables/table_format.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

namespace {

// The loader needs an 8-byte aligned buffer. This one has exactly the input's size, so ASan's
// redzones sit right after the last byte and catch any read past it.
constexpr std::align_val_t kTableAlignment{alignof(stencil::tables::BvhNode)};
struct AlignedFree {
  void operator()(std::byte* bytes) const { ::operator delete(bytes, kTableAlignment); }
};
using AlignedBytes = std::unique_ptr<std::byte, AlignedFree>;

AlignedBytes aligned_copy(const std::uint8_t* data, std::size_t size) {
  AlignedBytes copy(static_cast<std::byte*>(::operator new(size, kTableAlignment)));
  if (size > 0) {
    std::memcpy(copy.get(), data, size);
  }
  return copy;
}

double coordinate_sum(const stencil::tables::PackedPoint& point) {
  return static_cast<double>(point.x_mm) + static_cast<double>(point.y_mm) + static_cast<double>(point.z_mm);
}

// Reads every element of every view (ASan reports a view that runs past the buffer) and checks
// what the loader promises about the indices in them.
void walk(const stencil::tables::PartTables& tables) {
  using namespace stencil::tables;
  double sum = 0.0;
  std::uint64_t bits = 0;
  for (std::uint32_t i = 0; i < tables.point_count(); ++i) {
    sum += coordinate_sum(tables.points[i]);
    require(tables.triangle_ids[i] < tables.triangle_count());
    bits += tables.point_flags[i];
  }
  for (std::uint32_t i = 0; i < tables.triangle_count(); ++i) {
    for (const PackedPoint& vertex : tables.triangles[i].vertices) {
      sum += coordinate_sum(vertex);
    }
    bits += tables.triangle_flags[i];
  }
  for (std::uint32_t i = 0; i < tables.node_count(); ++i) {
    const BvhNode& node = tables.nodes[i];
    for (std::size_t slab = 0; slab < std::size(node.dop_min); ++slab) {
      sum += node.dop_min[slab] + node.dop_max[slab];
    }
    if (node.point_count > 0) {
      require(node.first_point < tables.point_count() && node.point_count <= tables.point_count() - node.first_point);
      require(node.leaf < tables.leaf_count());
      const LeafBlock& block = tables.leaves[node.leaf];
      require(block.first_point == node.first_point && block.point_count == node.point_count);
    } else {
      require(node.right_child > i && node.right_child < tables.node_count());
    }
    bits += node.leaf;
  }
  for (std::uint32_t i = 0; i < tables.leaf_count(); ++i) {
    const LeafBlock& block = tables.leaves[i];
    for (std::uint32_t lane = 0; lane < kMaxLeafPoints; ++lane) {
      sum += static_cast<double>(block.x_mm[lane]) + static_cast<double>(block.nz[lane]);
    }
    sum += static_cast<double>(block.radius_mm);
  }
  // Keeps the reads from being optimised away.
  volatile double sink_sum = sum;
  volatile std::uint64_t sink_bits = bits;
  static_cast<void>(sink_sum);
  static_cast<void>(sink_bits);
}

}  // namespace


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::tables;
  const AlignedBytes copy = aligned_copy(data, size);
  const std::span<const std::byte> bytes(copy.get(), size);
  // Random bytes almost never carry a matching CRC-32: re-seal it so the checks after it get fuzzed.
  if (size >= sizeof(TableHeader)) {
    const std::uint32_t crc = table_crc32(bytes);
    std::memcpy(copy.get() + offsetof(TableHeader, crc32), &crc, sizeof(crc));
  }
  PartTables tables;
  const TableLoadResult result = load_tables(bytes, tables);
  if (!result.ok) {
    // Refused: a named field and expectation, and nothing adopted.
    require(result.field != nullptr && result.expected != nullptr);
    require(tables.points == nullptr && tables.point_count() == 0 && tables.nodes == nullptr);
    return 0;
  }
  require(tables.point_count() > 0 && tables.triangle_count() > 0 && tables.node_count() > 0);
  walk(tables);
  return 0;
}
