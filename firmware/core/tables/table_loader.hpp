// Validates table bytes and adopts them as a PartTables, refusing anything malformed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/core/tables/part_tables.hpp"

namespace stencil::tables {

// Why a table was refused. field names the place ("header.magic", "points", "nodes.dop"...),
// expected says what it should have been, index is the element (or byte offset, for the header)
// and value the offending number where there is one.
struct TableLoadResult {
  bool ok;
  const char* field;
  const char* expected;
  std::uint64_t index;
  double value;
};

// Checks everything before anything uses the data: magic, version, sizes, CRC-32, every count
// against capacity, section offsets, every index in range, every float finite, the leaf blocks
// (their points the Points section's, normals of unit length, a sphere bounding each leaf), the
// tool spec and tree, and the BVH (children in range, depth-first order, leaves covering every
// point exactly once, every DOP bounding what is below it). On success `tables` views into
// `bytes`, which must stay alive and unchanged; on failure `tables` is left empty (no points).
// Allocation-free; linear in the size of the table. Init-time only: not for the 1 kHz cycle.
[[nodiscard]] TableLoadResult load_tables(std::span<const std::byte> bytes, PartTables& tables);

// The `expected` of the refusal of a table of an older format version, by which the programs
// recognise it and say "format version N: regenerate with stencil-tablegen".
extern const char* const kOlderVersion;

// CRC-32 (zlib's polynomial) of the bytes that the header's crc32 field covers.
[[nodiscard]] std::uint32_t table_crc32(std::span<const std::byte> bytes);

}  // namespace stencil::tables
