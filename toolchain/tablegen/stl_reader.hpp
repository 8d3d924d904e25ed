// Reads ASCII and binary STL into triangles, with errors that name the file and the facet or line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace stencil::tablegen {

struct StlTriangle {
  Eigen::Vector3d vertices[3];  // as in the file (STL units)
  Eigen::Vector3d file_normal;  // as in the file; may be zero
};

enum class StlFormat { Ascii, Binary };

struct StlMesh {
  StlFormat format;
  std::vector<StlTriangle> triangles;  // every facet of the file, in file order
  std::size_t solid_count;             // ASCII: how many solid ... endsolid blocks (all are read)
};

// Parses the bytes of an STL file named `file_name` (used in messages only). Binary is recognised
// by its size (84 + 50 * count), even when it begins with "solid"; otherwise a file that begins with
// "solid" is ASCII; anything else is refused. Every facet must have three finite vertices.
// Throws InputError naming the file and the facet (binary: with its byte offset) or line (ASCII).
StlMesh parse_stl(std::span<const std::byte> bytes, const std::string& file_name);

// The whole file's bytes; InputError naming the path when it cannot be read.
std::vector<std::byte> read_file_bytes(const std::string& path);

}  // namespace stencil::tablegen
