// The exact point-triangle, segment-segment and segment-triangle distances against cases worked by
// hand: each Voronoi region of a triangle, parallel, skew and degenerate segments, a segment through
// a triangle, beside an edge, and parallel above the face.
#include <cmath>

#include "sim/mill/triangle_distance.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using Eigen::Vector3d;

namespace {

// The right triangle (0,0,0) (2,0,0) (0,2,0) in the plane z = 0.
const Vector3d kA(0.0, 0.0, 0.0);
const Vector3d kB(2.0, 0.0, 0.0);
const Vector3d kC(0.0, 2.0, 0.0);

void check_closest(const Vector3d& expected, const Vector3d& p) {
  const Vector3d got = closest_on_triangle(p, kA, kB, kC);
  DOUBLES_EQUAL(expected.x(), got.x(), 1e-12);
  DOUBLES_EQUAL(expected.y(), got.y(), 1e-12);
  DOUBLES_EQUAL(expected.z(), got.z(), 1e-12);
}

}  // namespace

TEST_GROUP(TriangleDistance){};

TEST(TriangleDistance, TheClosestPointIsFoundInEveryRegionOfTheTriangle) {
  check_closest({0.5, 0.5, 0.0}, {0.5, 0.5, 3.0});     // over the face
  check_closest(kA, {-1.0, -1.0, 1.0});                // beyond each corner
  check_closest(kB, {3.0, -1.0, 0.0});
  check_closest(kC, {-1.0, 3.0, 0.0});
  check_closest({1.0, 0.0, 0.0}, {1.0, -2.0, 1.0});    // beyond each edge
  check_closest({0.0, 1.5, 0.0}, {-1.0, 1.5, 0.0});
  check_closest({1.5, 0.5, 0.0}, {2.5, 1.5, -1.0});    // the hypotenuse x + y = 2
}

TEST(TriangleDistance, SegmentToSegmentDistancesHandleSkewParallelAndDegenerateSegments) {
  // Skew: x axis at z = 0 against a y-parallel segment at z = 1 crossing over it.
  DOUBLES_EQUAL(1.0, segment_segment_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 1}, {0, 1, 1}), 1e-12);
  // Skew, but the nearest points would lie beyond an end: clamped to the end.
  DOUBLES_EQUAL(std::sqrt(2.0), segment_segment_distance({0, 0, 0}, {1, 0, 0}, {2, -1, 1}, {2, 1, 1}), 1e-12);
  // The lines' nearest points lie past the second segment's end: that end, and the first segment's
  // point nearest it (3, 0, 0).
  DOUBLES_EQUAL(std::sqrt(2.0), segment_segment_distance({0, 0, 0}, {4, 0, 0}, {1, -3, 1}, {3, -1, 1}), 1e-12);
  // Parallel, overlapping.
  DOUBLES_EQUAL(0.5, segment_segment_distance({0, 0, 0}, {2, 0, 0}, {1, 0.5, 0}, {3, 0.5, 0}), 1e-12);
  // Collinear with a gap.
  DOUBLES_EQUAL(1.0, segment_segment_distance({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}), 1e-12);
  // Points.
  DOUBLES_EQUAL(5.0, segment_segment_distance({0, 0, 0}, {0, 0, 0}, {3, 4, 0}, {3, 4, 0}), 1e-12);
  DOUBLES_EQUAL(1.0, segment_segment_distance({0, 0, 1}, {0, 0, 1}, {-1, 0, 0}, {1, 0, 0}), 1e-12);
}

TEST(TriangleDistance, ASegmentThroughTheTriangleIsAtDistanceZero) {
  DOUBLES_EQUAL(0.0, segment_triangle_distance({0.5, 0.5, -1.0}, {0.5, 0.5, 1.0}, kA, kB, kC), 0.0);
  // Ending exactly on the face counts too.
  DOUBLES_EQUAL(0.0, segment_triangle_distance({0.5, 0.5, 1.0}, {0.5, 0.5, 0.0}, kA, kB, kC), 0.0);
}

TEST(TriangleDistance, ASegmentCrossingTheTrianglesPlaneOutsideItIsItsDistanceToTheNearestEdge) {
  // Through the plane at (1, -1): the nearest edge is AB (y = 0), 1 mm away in y.
  DOUBLES_EQUAL(1.0, segment_triangle_distance({1.0, -1.0, -1.0}, {1.0, -1.0, 1.0}, kA, kB, kC), 1e-12);
}

TEST(TriangleDistance, ASegmentParallelAboveTheFaceIsItsHeightAway) {
  DOUBLES_EQUAL(0.75, segment_triangle_distance({0.2, 0.2, 0.75}, {1.0, 0.5, 0.75}, kA, kB, kC), 1e-12);
  // And one that runs out beyond the triangle at both ends: its middle is over the face.
  DOUBLES_EQUAL(0.25, segment_triangle_distance({1.0, -1.0, 0.25}, {1.0, 3.0, 0.25}, kA, kB, kC), 1e-12);
}
