// The baked-in table: the hex prism's table, emitted as C++ by stencil-tablegen --emit-cpp and linked
// with linker/stencil_tables.ld, lies inside the .stencil_tables bounds, 64-byte aligned, and loads.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>

#include "firmware/core/tables/table_loader.hpp"

// From the emitted stencil_table_hex_prism.cpp.
extern const unsigned char stencil_table_hex_prism[];
extern const std::size_t stencil_table_hex_prism_size;

// From linker/stencil_tables.ld: the bounds of the output section.
extern "C" const unsigned char __stencil_tables_start[];
extern "C" const unsigned char __stencil_tables_end[];

int main() {
  const auto table = reinterpret_cast<std::uintptr_t>(stencil_table_hex_prism);
  const auto start = reinterpret_cast<std::uintptr_t>(__stencil_tables_start);
  const auto end = reinterpret_cast<std::uintptr_t>(__stencil_tables_end);
  const std::size_t size = stencil_table_hex_prism_size;
  std::printf("baked table: %zu bytes at %#zx; .stencil_tables [%#zx, %#zx)\n", size, static_cast<std::size_t>(table),
              static_cast<std::size_t>(start), static_cast<std::size_t>(end));

  int failures = 0;
  if (size == 0) {
    std::printf("FAIL: stencil_table_hex_prism_size is 0; expected the table's size\n");
    ++failures;
  }
  if (table < start || end < start || size > end - start || table - start > end - start - size) {
    std::printf("FAIL: the table [%#zx, %#zx) is not inside .stencil_tables [%#zx, %#zx); expected the linker "
                "script to place it there\n",
                static_cast<std::size_t>(table), static_cast<std::size_t>(table + size), static_cast<std::size_t>(start),
                static_cast<std::size_t>(end));
    ++failures;
  }
  if (table % 64 != 0 || start % 64 != 0) {
    std::printf("FAIL: the table (%#zx) and the section start (%#zx) must be 64-byte aligned\n",
                static_cast<std::size_t>(table), static_cast<std::size_t>(start));
    ++failures;
  }

  stencil::tables::PartTables part{};
  const stencil::tables::TableLoadResult result = stencil::tables::load_tables(
      std::span<const std::byte>(reinterpret_cast<const std::byte*>(stencil_table_hex_prism), size), part);
  if (!result.ok) {
    std::printf("FAIL: load_tables refused the baked table: %s (at %llu): expected %s; found %.17g\n", result.field,
                static_cast<unsigned long long>(result.index), result.expected, result.value);
    ++failures;
  } else {
    std::printf("load_tables: %u points, %u triangles, %u nodes\n", part.point_count(), part.triangle_count(),
                part.node_count());
    if (reinterpret_cast<std::uintptr_t>(part.points) < table ||
        reinterpret_cast<std::uintptr_t>(part.nodes) >= table + size) {
      std::printf("FAIL: the loaded views do not point into the baked table; expected in-place views\n");
      ++failures;
    }
  }
  return failures == 0 ? 0 : 1;
}
