// The point cloud: every surface point within h of a sample, counts as promised, seeded and thread-blind.
#include <cmath>
#include <random>
#include <vector>

#include "tests/support/sample_tables.hpp"
#include "tests/support/stl_meshes.hpp"
#include "toolchain/tablegen/point_cloud.hpp"
#include "toolchain/tablegen/sample_parts.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::tablegen;
using stencil::geometry::CutterKind;
using stencil::geometry::ToolSpec;

namespace {

PartMesh mesh_of(const std::vector<Facet>& facets) { return prepare_part(stencil::test::mesh_of(facets), stencil::test::rig_placement(), "part.stl"); }

// Awkward triangles: acute, right, very obtuse (a sliver) and large.
std::vector<Facet> awkward_facets() {
  return {
      {Eigen::Vector3d(10, 10, 1), Eigen::Vector3d(13, 10.5, 1.2), Eigen::Vector3d(11, 13, 0.8)},
      {Eigen::Vector3d(20, 5, 2), Eigen::Vector3d(24, 5, 2), Eigen::Vector3d(20, 8, 2)},
      {Eigen::Vector3d(5, 20, 3), Eigen::Vector3d(15, 20.3, 3), Eigen::Vector3d(25, 20, 3)},
      {Eigen::Vector3d(30, 2, 0), Eigen::Vector3d(48, 4, 5), Eigen::Vector3d(35, 22, 10)},
  };
}

CloudOptions options_with(double h, unsigned threads = 1) {
  CloudOptions options;
  options.covering_radius_mm = h;
  options.threads = threads;
  return options;
}

}  // namespace

TEST_GROUP(PointCloud){};

TEST(PointCloud, EverySurfacePointIsWithinTheCoveringRadiusOfASample) {
  const PartMesh mesh = mesh_of(awkward_facets());
  std::mt19937_64 random(41);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const double h : {0.9, 0.35}) {
    const PointCloud cloud = build_point_cloud(mesh, options_with(h), [](double) {});
    CHECK(cloud.achieved_covering_radius_mm <= h);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& v = mesh.triangles[t].vertices;
      for (int trial = 0; trial < 400; ++trial) {
        double a = unit(random);
        double b = unit(random);
        if (a + b > 1.0) {
          a = 1.0 - a;
          b = 1.0 - b;
        }
        const Eigen::Vector3d surface_point = v[0] + a * (v[1] - v[0]) + b * (v[2] - v[0]);
        double nearest = 1e9;
        for (const CloudPoint& point : cloud.points) {
          nearest = std::min(nearest, (point.position_mm - surface_point).norm());
        }
        CHECK(nearest <= cloud.achieved_covering_radius_mm + 1e-12);
      }
    }
  }
}

TEST(PointCloud, VerticesComeFirstThenCentroidsEachWithItsTrianglesNormal) {
  const PartMesh mesh = mesh_of(hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  const PointCloud cloud = build_point_cloud(mesh, options_with(0.5), [](double) {});
  LONGS_EQUAL(14, cloud.vertex_points);
  LONGS_EQUAL(count_cloud_points(mesh, options_with(0.5)), cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const CloudPoint& point = cloud.points[i];
    CHECK(point.triangle < mesh.triangles.size());
    CHECK((point.normal - mesh.triangles[point.triangle].normal).norm() == 0.0);
    if (i >= 14 && i < 14 + 24) {
      const auto& v = mesh.triangles[i - 14].vertices;
      CHECK((point.position_mm - (v[0] + v[1] + v[2]) / 3.0).norm() < 1e-12);
    }
  }
}

TEST(PointCloud, TheSameForAnyThreadCount) {
  const PartMesh mesh = mesh_of(awkward_facets());
  const PointCloud one = build_point_cloud(mesh, options_with(0.2, 1), [](double) {});
  const PointCloud two = build_point_cloud(mesh, options_with(0.2, 2), [](double) {});
  const PointCloud five = build_point_cloud(mesh, options_with(0.2, 5), [](double) {});
  LONGS_EQUAL(one.points.size(), two.points.size());
  LONGS_EQUAL(one.points.size(), five.points.size());
  for (std::size_t i = 0; i < one.points.size(); ++i) {
    CHECK(one.points[i].position_mm == two.points[i].position_mm);
    CHECK(one.points[i].position_mm == five.points[i].position_mm);
    CHECK(one.points[i].triangle == five.points[i].triangle);
  }
}

TEST(PointCloud, ExtraPointsAreSeededOnTheSurfaceAndAreaWeighted) {
  const PartMesh mesh = mesh_of(awkward_facets());
  CloudOptions options = options_with(5.0);
  options.extra_points = 4000;
  options.seed = 7;
  const PointCloud first = build_point_cloud(mesh, options, [](double) {});
  const PointCloud again = build_point_cloud(mesh, options, [](double) {});
  options.seed = 8;
  const PointCloud other = build_point_cloud(mesh, options, [](double) {});
  const std::size_t extra_start = first.points.size() - 4000;
  std::vector<double> share(mesh.triangles.size(), 0.0);
  bool differs = false;
  for (std::size_t i = extra_start; i < first.points.size(); ++i) {
    CHECK(first.points[i].position_mm == again.points[i].position_mm);
    differs = differs || first.points[i].position_mm != other.points[i].position_mm;
    const PartTriangle& triangle = mesh.triangles[first.points[i].triangle];
    // On the triangle's plane.
    DOUBLES_EQUAL(0.0, (first.points[i].position_mm - triangle.vertices[0]).dot(triangle.normal), 1e-9);
    share[first.points[i].triangle] += 1.0 / 4000.0;
  }
  CHECK(differs);
  double total_area = 0.0;
  for (const PartTriangle& triangle : mesh.triangles) {
    total_area += triangle.area_mm2;
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    DOUBLES_EQUAL(mesh.triangles[t].area_mm2 / total_area, share[t], 0.03);
  }
}

TEST(PointCloud, AllowanceMovesEveryPointOutAlongItsNormal) {
  const PartMesh mesh = mesh_of(hexagonal_prism(8.0, 6.0, 25.0, 12.5));
  CloudOptions options = options_with(1.0);
  const PointCloud plain = build_point_cloud(mesh, options, [](double) {});
  options.allowance_mm = 0.2;
  const PointCloud inflated = build_point_cloud(mesh, options, [](double) {});
  for (std::size_t i = 0; i < plain.points.size(); ++i) {
    CHECK((inflated.points[i].position_mm - plain.points[i].position_mm - 0.2 * plain.points[i].normal).norm() < 1e-12);
  }
}

TEST(PointCloud, GougeBoundIsTheSagittaOfTheRoundedEdgeAndItsInverseRoundTrips) {
  const ToolSpec ball{CutterKind::Ball, 3.0, 12.0, 0.0, 10.0, 20.0};
  const ToolSpec bull{CutterKind::BullNose, 6.0, 12.0, 1.0, 10.0, 20.0};
  const ToolSpec flat{CutterKind::Flat, 3.0, 12.0, 0.0, 10.0, 20.0};
  DOUBLES_EQUAL(1.5 - std::sqrt(1.5 * 1.5 - 0.1 * 0.1), gouge_bound_mm(ball, 0.1), 1e-15);
  DOUBLES_EQUAL(1.0 - std::sqrt(1.0 - 0.1 * 0.1), gouge_bound_mm(bull, 0.1), 1e-15);
  DOUBLES_EQUAL(0.1, gouge_bound_mm(flat, 0.1), 0.0);
  // About h^2 / 2R for small h.
  DOUBLES_EQUAL(0.01 / 3.0, gouge_bound_mm(ball, 0.1), 1e-5);
  for (const ToolSpec& tool : {ball, bull, flat}) {
    DOUBLES_EQUAL(0.004, gouge_bound_mm(tool, covering_radius_for_gouge(tool, 0.004)), 1e-12);
  }
  DOUBLES_EQUAL(std::sqrt(0.004 * (3.0 - 0.004)), covering_radius_for_gouge(ball, 0.004), 1e-15);
}
