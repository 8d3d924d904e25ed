// libFuzzer target: the STL reader and the part preparation refuse bad bytes with InputError, and nothing else.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/part_mesh.hpp"
#include "toolchain/tablegen/stl_reader.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

namespace {

// What parse_stl promises for every mesh it returns.
void check_mesh(const stencil::tablegen::StlMesh& mesh) {
  require(mesh.solid_count >= 1);
  require(!mesh.triangles.empty());  // a file with no facets is refused, binary or ASCII
  for (const stencil::tablegen::StlTriangle& triangle : mesh.triangles) {
    for (const Eigen::Vector3d& vertex : triangle.vertices) {
      require(vertex.allFinite());
    }
    require(triangle.file_normal.allFinite());
  }
}

// What prepare_part promises for every part it returns.
void check_part(const stencil::tablegen::PartMesh& part, const stencil::tablegen::PlacementOptions& options) {
  require(!part.triangles.empty());
  require(part.vertex_first_triangle.size() == part.vertices.size());
  for (const stencil::tablegen::PartTriangle& triangle : part.triangles) {
    require(triangle.normal.allFinite() && std::abs(triangle.normal.norm() - 1.0) < 1e-9);
    require(std::isfinite(triangle.area_mm2) && triangle.area_mm2 > 0.0);
    for (const std::uint32_t id : triangle.vertex_ids) {
      require(id < part.vertices.size());
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    // prepare_part refuses parts outside the workspace, with a tolerance of 1e-9 mm.
    require(part.min_mm[axis] <= part.max_mm[axis]);
    require(part.min_mm[axis] >= -1e-9 && part.max_mm[axis] <= options.workspace_mm[axis] + 1e-9);
  }
}

}  // namespace


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::tablegen;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  const std::string file_name = "fuzz.stl";
  StlMesh mesh;
  try {
    mesh = parse_stl(bytes, file_name);
  } catch (const InputError&) {
    return 0;  // refused as bad input: the expected outcome for most inputs
  }
  check_mesh(mesh);

  // Centred in a huge workspace, so that placement refuses only parts a billion millimetres across.
  PlacementOptions options;
  options.placement = Placement::Center;
  options.workspace_mm = {1e9, 1e9, 1e9};
  try {
    check_part(prepare_part(mesh, options, file_name), options);
  } catch (const InputError&) {
    return 0;
  }
  return 0;
}
