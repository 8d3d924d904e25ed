// Preparing the part: units, placement, degenerate facets, the workspace, and the mesh census.
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "toolchain/tablegen/input_error.hpp"
#include "toolchain/tablegen/part_mesh.hpp"
#include "tests/support/sample_tables.hpp"
#include "tests/support/stl_meshes.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::tablegen;
using stencil::test::mesh_of;
using stencil::test::rig_placement;

namespace {

std::string error_of(const StlMesh& stl, const PlacementOptions& options) {
  try {
    static_cast<void>(prepare_part(stl, options, "part.stl"));
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_GROUP(PartMesh){};

TEST(PartMesh, AClosedPrismHasNoDefectsAndAPositiveVolume) {
  const PartMesh mesh = prepare_part(mesh_of(hexagonal_prism(8.0, 6.0, 25.0, 12.5)), rig_placement(), "hex.stl");
  LONGS_EQUAL(24, mesh.triangles.size());
  LONGS_EQUAL(14, mesh.vertices.size());
  LONGS_EQUAL(0, mesh.report.open_edges);
  LONGS_EQUAL(0, mesh.report.non_manifold_edges);
  LONGS_EQUAL(0, mesh.report.inconsistent_edges);
  LONGS_EQUAL(0, mesh.report.normal_disagreements);
  // A hexagon of circumradius 8 has area 3 * sqrt(3) / 2 * 64; times the height 6.
  DOUBLES_EQUAL(3.0 * std::sqrt(3.0) / 2.0 * 64.0 * 6.0, mesh.report.signed_volume_mm3, 1e-9);
  for (const PartTriangle& triangle : mesh.triangles) {
    DOUBLES_EQUAL(1.0, triangle.normal.norm(), 1e-12);
  }
}

TEST(PartMesh, InwardNormalsAreReportedAndFlipTurnsThemOut) {
  auto facets = hexagonal_prism(8.0, 6.0, 25.0, 12.5);
  for (Facet& facet : facets) {
    std::swap(facet[1], facet[2]);
  }
  const PartMesh inward = prepare_part(mesh_of(facets), rig_placement(), "hex.stl");
  CHECK(inward.report.signed_volume_mm3 < 0.0);
  PlacementOptions flip = rig_placement();
  flip.flip = true;
  const PartMesh flipped = prepare_part(mesh_of(facets), flip, "hex.stl");
  CHECK(flipped.report.signed_volume_mm3 > 0.0);
  LONGS_EQUAL(0, flipped.report.normal_disagreements);  // the file's normals matched the file's winding
}

TEST(PartMesh, FileNormalsThatDisagreeAreCounted) {
  StlMesh stl = mesh_of(hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  stl.triangles[3].file_normal = -stl.triangles[3].file_normal;
  stl.triangles[4].file_normal = {0.0, 0.0, 0.0};  // no normal given: not a disagreement
  const PartMesh mesh = prepare_part(stl, rig_placement(), "hex.stl");
  LONGS_EQUAL(1, mesh.report.normal_disagreements);
}

TEST(PartMesh, DegenerateFacetsAreDroppedAndCountedAndAllDegenerateIsRefused) {
  auto facets = hexagonal_prism(8.0, 6.0, 25.0, 12.5);
  facets.push_back({facets[0][0], facets[0][0], facets[0][1]});                             // two equal corners
  facets.push_back({Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(2, 2, 2), Eigen::Vector3d(3, 3, 3)});  // collinear
  const PartMesh mesh = prepare_part(mesh_of(facets), rig_placement(), "hex.stl");
  LONGS_EQUAL(24, mesh.triangles.size());
  LONGS_EQUAL(2, mesh.report.degenerate_dropped);
  const std::vector<Facet> all_flat{{Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1)}};
  CHECK(error_of(mesh_of(all_flat), rig_placement()).find("all 1 facets are degenerate") != std::string::npos);
}

TEST(PartMesh, APartOutsideTheWorkspaceIsRefusedNamingTheAxis) {
  const StlMesh stl = mesh_of(hexagonal_prism(8.0, 6.0, 0.0, 0.0));  // centred on the origin
  const std::string message = error_of(stl, rig_placement());
  CHECK_TEXT(message.find("part.stl: the placed part spans x [-8, 8] mm, outside the workspace [0, 50] mm") !=
                 std::string::npos,
             message.c_str());
  PlacementOptions centre = rig_placement();
  centre.placement = Placement::Center;
  const PartMesh placed = prepare_part(stl, centre, "part.stl");
  DOUBLES_EQUAL(17.0, placed.min_mm.x(), 1e-12);
  DOUBLES_EQUAL(33.0, placed.max_mm.x(), 1e-12);
  DOUBLES_EQUAL(12.5, 0.5 * (placed.min_mm.y() + placed.max_mm.y()), 1e-12);
  DOUBLES_EQUAL(0.0, placed.min_mm.z(), 0.0);
  PlacementOptions too_tall = centre;
  too_tall.workspace_mm.z() = 5.0;
  CHECK(error_of(stl, too_tall).find("spans z [0, 6] mm") != std::string::npos);
}

TEST(PartMesh, InchesBecomeMillimetresThenTheScaleApplies) {
  PlacementOptions options = rig_placement();
  options.millimetres_per_unit = 25.4;
  options.scale = 0.5;
  const PartMesh mesh = prepare_part(mesh_of(hexagonal_prism(1.0, 0.5, 1.5, 1.0)), options, "hex.stl");
  DOUBLES_EQUAL(0.5 * 25.4 * 0.5, mesh.max_mm.z(), 1e-12);
  DOUBLES_EQUAL(0.5 * 25.4 * 2.5, mesh.max_mm.x(), 1e-12);
}

TEST(PartMesh, OpenNonManifoldAndInconsistentEdgesAreCounted) {
  const Eigen::Vector3d a(1, 1, 0), b(2, 1, 0), c(1, 2, 0), d(2, 2, 0), e(1.5, 1.5, 1);
  // One lone facet: three open edges.
  LONGS_EQUAL(3, prepare_part(mesh_of({{a, b, c}}), rig_placement(), "p.stl").report.open_edges);
  // Two facets sharing edge b-c, the second running the same way: inconsistent.
  const PartMesh twisted = prepare_part(mesh_of({{a, b, c}, {b, c, d}}), rig_placement(), "p.stl");
  LONGS_EQUAL(1, twisted.report.inconsistent_edges);
  LONGS_EQUAL(4, twisted.report.open_edges);
  // Three facets on edge a-b: non-manifold.
  const PartMesh fan = prepare_part(mesh_of({{a, b, c}, {b, a, e}, {a, b, d}}), rig_placement(), "p.stl");
  LONGS_EQUAL(1, fan.report.non_manifold_edges);
}
