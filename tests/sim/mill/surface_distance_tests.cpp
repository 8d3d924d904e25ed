// The distance to the part's surface against distances worked by hand, the sign of a height field's
// top point inside and outside a part, and the buckets against looking at every triangle.
#include <cmath>
#include <random>
#include <vector>

#include "sim/mill/surface_distance.hpp"
#include "sim/mill/triangle_distance.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;

namespace {

constexpr double kReach = 2.0;

// The unit cube [0, 1]^3 as twelve triangles.
std::vector<Triangle> unit_cube() {
  const auto corner = [](int i) { return Eigen::Vector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1); };
  // Each face as four corners in order round it.
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  std::vector<Triangle> triangles;
  for (const auto& face : faces) {
    triangles.push_back({corner(face[0]), corner(face[1]), corner(face[2])});
    triangles.push_back({corner(face[0]), corner(face[2]), corner(face[3])});
  }
  return triangles;
}

double brute_force(const std::vector<Triangle>& triangles, const Eigen::Vector3d& p) {
  double best = kReach;
  for (const Triangle& t : triangles) {
    best = std::min(best, (closest_on_triangle(p, t[0], t[1], t[2]) - p).norm());
  }
  return best;
}

}  // namespace

TEST_GROUP(SurfaceDistance){};

TEST(SurfaceDistance, APointAboveAFlatTriangleIsItsHeightAway) {
  const SurfaceDistance surface({{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(0, 4, 0)}}, kReach);
  DOUBLES_EQUAL(1.5, surface.distance({1.0, 1.0, 1.5}), 1e-12);
  // Beside the edge x = 0: across to it and down.
  DOUBLES_EQUAL(std::sqrt(2.0), surface.distance({-1.0, 1.0, 1.0}), 1e-12);
  DOUBLES_EQUAL(0.0, surface.distance({0.5, 0.5, 0.0}), 1e-12);
}

TEST(SurfaceDistance, APointOutOfReachIsReportedAtTheReach) {
  const SurfaceDistance surface({{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(0, 4, 0)}}, kReach);
  DOUBLES_EQUAL(kReach, surface.distance({1.0, 1.0, 5.0}), 0.0);
  DOUBLES_EQUAL(kReach, surface.distance({50.0, -30.0, 0.0}), 0.0);
  DOUBLES_EQUAL(kReach, SurfaceDistance({}, kReach).distance({0.0, 0.0, 0.0}), 0.0);
}

TEST(SurfaceDistance, ACellTopInsideACubeIsNegativeByItsDistanceToTheNearestFace) {
  const SurfaceDistance surface(unit_cube(), kReach);
  // One cell centred at (0.3, 0.5): its top 0.6 high is inside, 0.3 from the face x = 0 (the top is
  // 0.4 above it: the distance is 3-D, not vertical).
  const CellGrid grid{1, 1, 1.0, {-0.2, 0.0}};
  const std::vector<float> inside = signed_distances(surface, grid, {0.6}, {1.0});
  DOUBLES_EQUAL(-0.3, inside[0], 1e-6);
  const std::vector<float> above = signed_distances(surface, grid, {1.25}, {1.0});
  DOUBLES_EQUAL(0.25, above[0], 1e-6);
}

TEST(SurfaceDistance, CellsAreRowMajorAndFarOnesClampedAtTheReach) {
  const SurfaceDistance surface(unit_cube(), kReach);
  // Two columns, two rows of 1 mm from (0, 0), row-major: (0, 0) on the cube's top; (1, 0) on the
  // floor beside it, 0.5 from its side; (0, 1) 4 mm up, out of reach; (1, 1) 0.2 above the floor off
  // the cube's corner, 0.5 * sqrt(2) from its vertical edge.
  const CellGrid grid{2, 2, 1.0, {0.0, 0.0}};
  const std::vector<float> d = signed_distances(surface, grid, {1.0, 0.0, 4.0, 0.2}, {1.0, 0.0, 0.0, 0.0});
  DOUBLES_EQUAL(0.0, d[0], 1e-6);
  DOUBLES_EQUAL(0.5, d[1], 1e-6);
  DOUBLES_EQUAL(kReach, d[2], 1e-6);
  DOUBLES_EQUAL(std::sqrt(0.5 * 0.5 + 0.5 * 0.5), d[3], 1e-6);
}

TEST(SurfaceDistance, TheBucketsFindWhatLookingAtEveryTriangleFinds) {
  std::mt19937 random(2026);
  std::uniform_real_distribution<double> coordinate(0.0, 20.0), step(-1.5, 1.5);
  std::vector<Triangle> triangles;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d a(coordinate(random), coordinate(random), coordinate(random) / 4.0);
    triangles.push_back({a, a + Eigen::Vector3d(step(random), step(random), step(random)),
                         a + Eigen::Vector3d(step(random), step(random), step(random))});
  }
  const SurfaceDistance surface(triangles, kReach);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d p(coordinate(random) * 1.2 - 2.0, coordinate(random) * 1.2 - 2.0, coordinate(random) / 3.0);
    DOUBLES_EQUAL(brute_force(triangles, p), surface.distance(p), 1e-12);
  }
}
