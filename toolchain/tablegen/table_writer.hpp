// Assembles the .stbl bytes, writes them atomically, and emits them as C++ for a firmware image.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::tablegen {

struct TableContents {
  tables::TableHeader header;  // every descriptive field set; counts, sections, sizes and CRC are filled in
  geometry::ToolBsp tool;
  std::vector<tables::PackedPoint> points;
  std::vector<tables::PackedPoint> normals;  // in the table, in the leaf blocks
  std::vector<std::uint32_t> triangle_ids;
  std::vector<std::uint8_t> point_flags;
  std::vector<tables::PackedTriangle> triangles;
  std::vector<std::uint8_t> triangle_flags;
  std::vector<tables::BvhNode> nodes;        // assemble_table numbers the leaves' blocks
};

// Memory for a table, aligned as the loader needs it.
class TableBytes {
 public:
  explicit TableBytes(std::size_t size = 0);
  std::byte* data() { return storage_.data() + offset_; }
  const std::byte* data() const { return storage_.data() + offset_; }
  std::size_t size() const { return size_; }

 private:
  std::vector<std::byte> storage_;
  std::size_t offset_ = 0;
  std::size_t size_ = 0;
};

// Lays the table out (header, then 64-byte aligned sections) and seals it with the CRC-32.
[[nodiscard]] TableBytes assemble_table(TableContents& contents);

// The table as a C++ source file: the same bytes as a constant array <name> in section
// ".stencil_tables" (see linker/stencil_tables.ld), with its size in <name>_size.
[[nodiscard]] std::string table_as_cpp(const std::string& name, const TableBytes& bytes);

// Reads a whole file into aligned memory; throws InputError naming the path.
[[nodiscard]] TableBytes read_table_file(const std::string& path);

}  // namespace stencil::tablegen
