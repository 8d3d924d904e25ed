// STL meshes made straight from facets, for tests that skip the file format.
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "toolchain/tablegen/sample_parts.hpp"
#include "toolchain/tablegen/stl_reader.hpp"

namespace stencil::test {

// The facets as the STL reader would return them, with file normals from the winding.
inline tablegen::StlMesh mesh_of(const std::vector<tablegen::Facet>& facets) {
  tablegen::StlMesh mesh{tablegen::StlFormat::Ascii, {}, 1};
  for (const tablegen::Facet& facet : facets) {
    tablegen::StlTriangle triangle;
    for (std::size_t v = 0; v < 3; ++v) {
      triangle.vertices[v] = facet[v];
    }
    triangle.file_normal = (facet[1] - facet[0]).cross(facet[2] - facet[0]).normalized();
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

}  // namespace stencil::test
