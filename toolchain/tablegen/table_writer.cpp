// Table layout, atomic writing and C++ emission.
#include "toolchain/tablegen/table_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <Eigen/Core>

#include "firmware/core/tables/leaf_moments.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/core/tables/tool_section.hpp"
#include "toolchain/tablegen/file_io.hpp"
#include "toolchain/tablegen/input_error.hpp"

namespace stencil::tablegen {
namespace {

std::uint64_t align_up(std::uint64_t value) {
  return (value + tables::kSectionAlignment - 1) / tables::kSectionAlignment * tables::kSectionAlignment;
}

std::string system_error() { return std::strerror(errno); }

// A float no smaller than `value`.
float float_at_least(double value) {
  float rounded = static_cast<float>(value);
  return static_cast<double>(rounded) < value ? std::nextafter(rounded, std::numeric_limits<float>::infinity()) : rounded;
}

// The leaf blocks, one per leaf in the nodes' (depth-first) order, each leaf node numbered with
// its block. The sphere is centred on the leaf's box and its radius, measured from the stored float
// centre exactly as the loader measures it, is rounded up once more so no rounding can fail it.
std::vector<tables::LeafBlock> pack_leaves(TableContents& contents) {
  std::vector<tables::LeafBlock> leaves;
  for (tables::BvhNode& node : contents.nodes) {
    node.leaf = 0;
    if (node.point_count == 0) {
      continue;
    }
    node.leaf = static_cast<std::uint32_t>(leaves.size());
    tables::LeafBlock block{};
    block.first_point = node.first_point;
    block.point_count = node.point_count;
    Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d high = -low;
    for (std::uint32_t lane = 0; lane < tables::kMaxLeafPoints; ++lane) {
      const std::uint32_t i = node.first_point + std::min(lane, node.point_count - 1);
      const tables::PackedPoint& p = contents.points[i];
      const tables::PackedPoint& n = contents.normals[i];
      block.x_mm[lane] = p.x_mm;
      block.y_mm[lane] = p.y_mm;
      block.z_mm[lane] = p.z_mm;
      block.nx[lane] = n.x_mm;
      block.ny[lane] = n.y_mm;
      block.nz[lane] = n.z_mm;
      low = low.cwiseMin(Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm));
      high = high.cwiseMax(Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm));
    }
    const Eigen::Vector3d middle = 0.5 * (low + high);
    // Read back through volatile: GCC 12 at -O3 with AVX2 folds double(float(x)) to x here, and the
    // radius from the unrounded centre fell short of the stored one's by a float rounding.
    volatile float stored[3] = {static_cast<float>(middle.x()), static_cast<float>(middle.y()),
                                static_cast<float>(middle.z())};
    const Eigen::Vector3d centre(stored[0], stored[1], stored[2]);
    for (Eigen::Index axis = 0; axis < 3; ++axis) {
      block.centre_mm[axis] = static_cast<float>(centre[axis]);
    }
    double radius = 0.0;
    for (std::uint32_t lane = 0; lane < node.point_count; ++lane) {
      const tables::PackedPoint& p = contents.points[node.first_point + lane];
      radius = std::max(radius, (Eigen::Vector3d(p.x_mm, p.y_mm, p.z_mm) - centre).norm());
    }
    block.radius_mm = std::nextafter(float_at_least(radius), std::numeric_limits<float>::infinity());
    tables::store_moments(tables::leaf_moments(block), block);
    leaves.push_back(block);
  }
  return leaves;
}

}  // namespace

TableBytes::TableBytes(std::size_t size) : storage_(size + tables::kSectionAlignment), size_(size) {
  const auto address = reinterpret_cast<std::uintptr_t>(storage_.data());
  offset_ = (tables::kSectionAlignment - address % tables::kSectionAlignment) % tables::kSectionAlignment;
}

TableBytes assemble_table(TableContents& contents) {
  tables::TableHeader& header = contents.header;
  std::memcpy(header.magic, tables::kTableMagic, sizeof(header.magic));
  header.format_version = tables::kTableFormatVersion;
  header.header_bytes = sizeof(tables::TableHeader);
  header.flags = 0;
  header.point_count = static_cast<std::uint32_t>(contents.points.size());
  header.triangle_count = static_cast<std::uint32_t>(contents.triangles.size());
  header.node_count = static_cast<std::uint32_t>(contents.nodes.size());
  const std::vector<tables::LeafBlock> leaves = pack_leaves(contents);
  header.leaf_count = static_cast<std::uint32_t>(leaves.size());

  tables::ToolSection tool_section;
  tables::encode_tool_section(contents.tool, tool_section);

  struct Source {
    const void* data;
    std::size_t bytes;
  };
  const Source sources[tables::kSectionCount] = {
      {&tool_section, sizeof(tool_section)},
      {contents.points.data(), contents.points.size() * sizeof(tables::PackedPoint)},
      {leaves.data(), leaves.size() * sizeof(tables::LeafBlock)},
      {contents.triangle_ids.data(), contents.triangle_ids.size() * sizeof(std::uint32_t)},
      {contents.point_flags.data(), contents.point_flags.size()},
      {contents.triangles.data(), contents.triangles.size() * sizeof(tables::PackedTriangle)},
      {contents.triangle_flags.data(), contents.triangle_flags.size()},
      {contents.nodes.data(), contents.nodes.size() * sizeof(tables::BvhNode)},
  };
  std::uint64_t offset = align_up(sizeof(tables::TableHeader));
  for (std::size_t section = 0; section < tables::kSectionCount; ++section) {
    header.sections[section] = {offset, sources[section].bytes};
    offset = align_up(offset + sources[section].bytes);
  }
  header.file_bytes = offset;

  TableBytes bytes(offset);
  std::memset(bytes.data(), 0, bytes.size());
  for (std::size_t section = 0; section < tables::kSectionCount; ++section) {
    if (sources[section].bytes > 0) {
      std::memcpy(bytes.data() + header.sections[section].offset, sources[section].data, sources[section].bytes);
    }
  }
  header.crc32 = 0;
  std::memcpy(bytes.data(), &header, sizeof(header));
  header.crc32 = tables::table_crc32({bytes.data(), bytes.size()});
  std::memcpy(bytes.data(), &header, sizeof(header));
  return bytes;
}

std::string table_as_cpp(const std::string& name, const TableBytes& bytes) {
  std::ostringstream source;
  source << "// Generated by stencil-tablegen --emit-cpp: the part table " << name
         << " baked into the firmware image. Do not edit.\n"
         << "#include <cstddef>\n\n"
         << "extern const unsigned char " << name << "[];\n"
         << "extern const std::size_t " << name << "_size;\n\n"
         << "// In its own section so the linker script linker/stencil_tables.ld can place and bound it.\n"
         << "alignas(64) const unsigned char " << name << "[] __attribute__((section(\".stencil_tables\"), used)) = {";
  static const char* kHex = "0123456789abcdef";
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i % 16 == 0) {
      source << "\n   ";
    }
    const auto value = static_cast<unsigned>(bytes.data()[i]);
    source << " 0x" << kHex[value >> 4] << kHex[value & 15] << ',';
  }
  source << "\n};\n"
         << "const std::size_t " << name << "_size = " << bytes.size() << ";\n";
  return source.str();
}

TableBytes read_table_file(const std::string& path) {
  static_cast<void>(regular_file_size(path));  // refuses directories and missing files by name
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError(path + ": cannot open (" + system_error() + ")");
  }
  file.seekg(0, std::ios::end);
  const std::streamoff size = file.tellg();
  if (size < 0) {
    throw InputError(path + ": cannot read (not a regular file?)");
  }
  file.seekg(0, std::ios::beg);
  TableBytes bytes(static_cast<std::size_t>(size));
  if (size > 0 && !file.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw InputError(path + ": cannot read (" + system_error() + ")");
  }
  return bytes;
}

}  // namespace stencil::tablegen
