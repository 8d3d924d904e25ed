#include "firmware/core/tables/leaf_moments.hpp"

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

}  // namespace stencil::tables
