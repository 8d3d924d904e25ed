#include "firmware/core/tables/leaf_moments.hpp"

#include <algorithm>
#include <cmath>

#include <CppUTest/TestHarness.h>

namespace stencil::tables {

TEST_GROUP(LeafMoments){};

// The centroid and the mean normal over the leaf's own points: the lanes past its count (which
// repeat its last point) do not weigh in.
TEST(LeafMoments, AreTheMeansOfTheLeafsOwnPointsNotOfTheRepeatedLanes) {
  LeafBlock block{};
  block.point_count = 3;
  const float xs[3] = {1.0F, 2.0F, 6.0F};
  for (std::uint32_t lane = 0; lane < kMaxLeafPoints; ++lane) {
    const std::uint32_t i = lane < 3 ? lane : 2;
    block.x_mm[lane] = xs[i];
    block.y_mm[lane] = -2.0F * xs[i];
    block.z_mm[lane] = 10.0F;
    block.nx[lane] = i == 0 ? 1.0F : 0.0F;
    block.nz[lane] = i == 0 ? 0.0F : 1.0F;
  }
  const LeafMoments moments = leaf_moments(block);
  DOUBLES_EQUAL(3.0, moments.centroid_mm[0], 0.0);
  DOUBLES_EQUAL(-6.0, moments.centroid_mm[1], 0.0);
  DOUBLES_EQUAL(10.0, moments.centroid_mm[2], 0.0);
  DOUBLES_EQUAL(1.0 / 3.0, moments.mean_normal[0], 1e-7);  // shorter than 1: the normals differ
  DOUBLES_EQUAL(0.0, moments.mean_normal[1], 0.0);
  DOUBLES_EQUAL(2.0 / 3.0, moments.mean_normal[2], 1e-7);
}

// Summed in double and rounded once: far from the origin, a float running sum would lose the
// small offsets that tell the points apart.
TEST(LeafMoments, KeepTheCentroidOfPointsFarFromTheOriginToAFloatsRounding) {
  LeafBlock block{};
  block.point_count = kMaxLeafPoints;
  for (std::uint32_t lane = 0; lane < kMaxLeafPoints; ++lane) {
    block.x_mm[lane] = 1000.0F + 0.001F * static_cast<float>(lane);
    block.nz[lane] = 1.0F;
  }
  const LeafMoments moments = leaf_moments(block);
  double expected = 0.0;
  for (std::uint32_t lane = 0; lane < kMaxLeafPoints; ++lane) {
    expected += double{block.x_mm[lane]};
  }
  expected /= kMaxLeafPoints;
  CHECK(moments.centroid_mm[0] == static_cast<float>(expected));
  DOUBLES_EQUAL(1.0, moments.mean_normal[2], 0.0);
}

TEST(LeafMoments, OfALeafWithNoPointsAreZero) {
  LeafBlock block{};
  block.x_mm[0] = 5.0F;
  const LeafMoments moments = leaf_moments(block);
  DOUBLES_EQUAL(0.0, moments.centroid_mm[0], 0.0);
}

// Each group of kLeafGroupPoints lanes: its own points' means, a radius holding each of them from
// the centroid as stored, and zeros for a group past the leaf's points.
TEST(LeafMoments, OfEachGroupAreItsOwnPointsMeansAndTheRadiusHoldingThem) {
  LeafBlock block{};
  block.point_count = kLeafGroupPoints + 5;  // a full group, then five points
  for (std::uint32_t lane = 0; lane < kMaxLeafPoints; ++lane) {
    const std::uint32_t i = std::min(lane, block.point_count - 1);
    const bool first = i < kLeafGroupPoints;
    block.x_mm[lane] = (first ? 100.0F : 200.0F) + 0.1F * static_cast<float>(i % 7);
    block.y_mm[lane] = 0.01F * static_cast<float>(i);
    block.z_mm[lane] = first ? 1.0F : 2.0F;
    block.nx[lane] = first ? 1.0F : 0.0F;
    block.nz[lane] = first ? 0.0F : 1.0F;
  }
  const LeafMoments moments = leaf_moments(block);
  for (std::uint32_t group = 0; group < 2; ++group) {
    const LeafGroupMoments& g = moments.groups[group];
    const std::uint32_t first = group * kLeafGroupPoints;
    const std::uint32_t last = std::min(first + kLeafGroupPoints, block.point_count);
    double sum_x = 0.0;
    double farthest = 0.0;
    for (std::uint32_t lane = first; lane < last; ++lane) {
      sum_x += double{block.x_mm[lane]};
    }
    CHECK(g.centroid_mm[0] == static_cast<float>(sum_x / static_cast<double>(last - first)));
    DOUBLES_EQUAL(group == 0 ? 1.0 : 2.0, g.centroid_mm[2], 0.0);
    DOUBLES_EQUAL(group == 0 ? 1.0 : 0.0, g.mean_normal[0], 0.0);
    DOUBLES_EQUAL(group == 0 ? 0.0 : 1.0, g.mean_normal[2], 0.0);
    for (std::uint32_t lane = first; lane < last; ++lane) {
      const double dx = double{block.x_mm[lane]} - double{g.centroid_mm[0]};
      const double dy = double{block.y_mm[lane]} - double{g.centroid_mm[1]};
      const double dz = double{block.z_mm[lane]} - double{g.centroid_mm[2]};
      farthest = std::max(farthest, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    CHECK(double{g.radius_mm} >= farthest);                                   // holds every point
    CHECK(double{std::nextafter(g.radius_mm, 0.0F)} < farthest);             // and is the least float that does
  }
  for (std::uint32_t group = 2; group < kLeafGroups; ++group) {
    DOUBLES_EQUAL(0.0, moments.groups[group].centroid_mm[0], 0.0);
    DOUBLES_EQUAL(0.0, moments.groups[group].mean_normal[2], 0.0);
    DOUBLES_EQUAL(0.0, moments.groups[group].radius_mm, 0.0);
  }
}

}  // namespace stencil::tables
