// The part as the controller will see it: STL triangles in world millimetres, placed in the
// workspace, with degenerate facets dropped, normals recomputed and the mesh's defects counted.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "toolchain/tablegen/stl_reader.hpp"

namespace stencil::tablegen {

enum class Placement { AsIs, Center };

struct PlacementOptions {
  double millimetres_per_unit = 1.0;  // 25.4 for --units in
  double scale = 1.0;                 // --scale, applied after the units
  Placement placement = Placement::AsIs;
  // The rig's machine workspace, the box [0,X]x[0,Y]x[0,Z] (the caller's: the program's is the rig's,
  // rig_defaults.hpp). Not a number until given: refused.
  Eigen::Vector3d workspace_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool flip = false;                  // reverse every facet (for meshes whose normals point inward)
};

struct PartTriangle {
  std::array<Eigen::Vector3d, 3> vertices;  // world mm, counter-clockwise seen from outside
  Eigen::Vector3d normal;                   // unit, right-hand rule
  double area_mm2;
  std::array<std::uint32_t, 3> vertex_ids;  // into PartMesh::vertices
};

struct MeshReport {
  std::size_t source_triangles = 0;
  std::size_t solid_count = 0;
  std::size_t degenerate_dropped = 0;
  std::size_t normal_disagreements = 0;  // file normal more than 10 degrees from the recomputed one
  std::size_t open_edges = 0;            // used by one facet
  std::size_t non_manifold_edges = 0;    // used by more than two facets
  std::size_t inconsistent_edges = 0;    // two facets running the same way along a shared edge
  double signed_volume_mm3 = 0.0;        // about the part's centre: negative when normals mostly point inward
};

struct PartMesh {
  std::vector<PartTriangle> triangles;
  std::vector<Eigen::Vector3d> vertices;  // distinct vertices (equal coordinates welded)
  std::vector<std::uint32_t> vertex_first_triangle;  // the lowest-numbered triangle using each vertex
  Eigen::Vector3d min_mm;
  Eigen::Vector3d max_mm;
  MeshReport report;
};

// Converts, places and checks. Throws InputError naming the file when every facet is degenerate or
// the placed part does not fit the workspace.
PartMesh prepare_part(const StlMesh& stl, const PlacementOptions& options, const std::string& file_name);

}  // namespace stencil::tablegen
