// The 14-DOP against brute force: exact polytope intersection, containment of every input.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/LU>

#include "firmware/core/geometry/kdop14.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::geometry;

namespace {

Eigen::Vector3d slab_direction(std::size_t slab) {
  return {kKdopSlabDirections[slab][0], kKdopSlabDirections[slab][1], kKdopSlabDirections[slab][2]};
}

// Whether the two polytopes share a point, by brute force: their intersection is the polytope of
// the tighter bound on each slab; it is non-empty exactly when one of its candidate vertices (any
// three of the 14 planes meeting in a point) satisfies all 14 half-spaces.
bool polytopes_intersect(const Kdop14& a, const Kdop14& b) {
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> offsets;
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    const double low = std::max(a.min[slab], b.min[slab]);
    const double high = std::min(a.max[slab], b.max[slab]);
    if (low > high) {
      return false;
    }
    normals.push_back(slab_direction(slab));
    offsets.push_back(high);
    normals.push_back(-slab_direction(slab));
    offsets.push_back(-low);
  }
  const std::size_t count = normals.size();
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = i + 1; j < count; ++j) {
      for (std::size_t k = j + 1; k < count; ++k) {
        Eigen::Matrix3d planes;
        planes.row(0) = normals[i];
        planes.row(1) = normals[j];
        planes.row(2) = normals[k];
        if (std::abs(planes.determinant()) < 1e-9) {
          continue;
        }
        const Eigen::Vector3d vertex = planes.inverse() * Eigen::Vector3d(offsets[i], offsets[j], offsets[k]);
        bool feasible = true;
        for (std::size_t m = 0; m < count && feasible; ++m) {
          feasible = normals[m].dot(vertex) <= offsets[m] + 1e-9;
        }
        if (feasible) {
          return true;
        }
      }
    }
  }
  return false;
}

std::vector<Eigen::Vector3d> random_cloud(std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> centre(0.0, 3.0);
  std::uniform_real_distribution<double> offset(-spread, spread);
  std::uniform_int_distribution<int> count(1, 12);
  const Eigen::Vector3d middle(centre(rng), centre(rng), centre(rng));
  std::vector<Eigen::Vector3d> points;
  const int n = count(rng);
  for (int i = 0; i < n; ++i) {
    points.push_back(middle + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
  }
  return points;
}

}  // namespace

TEST_GROUP(Kdop14){};

TEST(Kdop14, OverlapNeverMissesAnIntersectionFoundByBruteForce) {
  std::mt19937_64 rng(11);
  int intersecting = 0;
  int disjoint = 0;
  int conservative = 0;  // said "overlap" where the polytopes miss each other along an edge direction
  for (int pair = 0; pair < 5000; ++pair) {
    const auto cloud_a = random_cloud(rng, 1.0);
    const auto cloud_b = random_cloud(rng, 1.0);
    const Kdop14 a = kdop_of_points(cloud_a);
    const Kdop14 b = kdop_of_points(cloud_b);
    const bool exact = polytopes_intersect(a, b);
    const bool tested = overlaps(a, b);
    CHECK_EQUAL(tested, overlaps(b, a));
    if (exact) {
      CHECK_TRUE(tested);
      ++intersecting;
    } else {
      ++disjoint;
      conservative += tested ? 1 : 0;
    }
  }
  CHECK(intersecting > 1000);
  CHECK(disjoint > 1000);
  // Seven slabs separate nearly every disjoint pair; the rest are edge-edge near misses.
  CHECK(conservative < disjoint / 20);
}

TEST(Kdop14, OverlapIsTheSevenIntervalTests) {
  std::mt19937_64 rng(12);
  for (int pair = 0; pair < 5000; ++pair) {
    const Kdop14 a = kdop_of_points(random_cloud(rng, 1.0));
    const Kdop14 b = kdop_of_points(random_cloud(rng, 1.0));
    bool every_interval_overlaps = true;
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      every_interval_overlaps = every_interval_overlaps && a.min[slab] <= b.max[slab] && b.min[slab] <= a.max[slab];
    }
    CHECK_EQUAL(every_interval_overlaps, overlaps(a, b));
  }
}

TEST(Kdop14, BuiltVolumeHoldsEveryPointAndEachBoundIsReached) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 1000; ++trial) {
    const auto cloud = random_cloud(rng, 2.0);
    const Kdop14 volume = kdop_of_points(cloud);
    CHECK_FALSE(volume.is_empty());
    for (const auto& point : cloud) {
      CHECK(volume.contains(point));
    }
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      double low = std::numeric_limits<double>::infinity();
      double high = -low;
      for (const auto& point : cloud) {
        low = std::min(low, slab_direction(slab).dot(point));
        high = std::max(high, slab_direction(slab).dot(point));
      }
      DOUBLES_EQUAL(low, volume.min[slab], 1e-12);
      DOUBLES_EQUAL(high, volume.max[slab], 1e-12);
    }
  }
}

TEST(Kdop14, MergedVolumeIsTheVolumeOfBothPointSets) {
  std::mt19937_64 rng(14);
  for (int trial = 0; trial < 1000; ++trial) {
    auto cloud_a = random_cloud(rng, 1.0);
    const auto cloud_b = random_cloud(rng, 1.0);
    const Kdop14 both = merged(kdop_of_points(cloud_a), kdop_of_points(cloud_b));
    cloud_a.insert(cloud_a.end(), cloud_b.begin(), cloud_b.end());
    const Kdop14 expected = kdop_of_points(cloud_a);
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      DOUBLES_EQUAL(expected.min[slab], both.min[slab], 0.0);
      DOUBLES_EQUAL(expected.max[slab], both.max[slab], 0.0);
    }
    for (const auto& point : cloud_a) {
      CHECK(both.contains(point));
    }
  }
}

TEST(Kdop14, EnlargedVolumeHoldsEveryPointWithinTheMargin) {
  std::mt19937_64 rng(15);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    const auto cloud = random_cloud(rng, 1.0);
    const double margin = 0.5 * fraction(rng);
    const Kdop14 volume = kdop_of_points(cloud).enlarged(margin);
    for (const auto& point : cloud) {
      const Eigen::Vector3d direction = Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
      CHECK(volume.contains(point + margin * direction, 1e-12));
    }
    // And no further: along the x slab, a point one margin beyond the outermost point is on the edge.
    const auto outermost = *std::max_element(cloud.begin(), cloud.end(),
                                             [](const auto& p, const auto& q) { return p.x() < q.x(); });
    CHECK_FALSE(volume.contains(outermost + Eigen::Vector3d(margin + 1e-9, 0.0, 0.0)));
  }
}

TEST(Kdop14, EmptyVolumeOverlapsNothingAndHoldsNothing) {
  const Kdop14 empty = Kdop14::empty();
  CHECK_TRUE(empty.is_empty());
  CHECK_TRUE(kdop_of_points({}).is_empty());
  const std::vector<Eigen::Vector3d> one_point{{1.0, 2.0, 3.0}};
  const Kdop14 point = kdop_of_points(one_point);
  CHECK_FALSE(point.is_empty());
  CHECK_FALSE(overlaps(empty, point));
  CHECK_FALSE(empty.contains({1.0, 2.0, 3.0}));
  CHECK_TRUE(overlaps(point, point));
}

TEST(Kdop14, ADamagedBoundReadsAsOverlapping) {
  // A NaN in a table must make the query look closer, never skip a leaf that may be in contact.
  const std::vector<Eigen::Vector3d> near{{0.0, 0.0, 0.0}};
  const std::vector<Eigen::Vector3d> far{{100.0, 100.0, 100.0}};
  Kdop14 damaged = kdop_of_points(far);
  const Kdop14 origin = kdop_of_points(near);
  for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
    damaged.min[slab] = std::numeric_limits<double>::quiet_NaN();
    damaged.max[slab] = std::numeric_limits<double>::quiet_NaN();
  }
  CHECK_TRUE(overlaps(damaged, origin));
  CHECK_TRUE(overlaps(origin, damaged));
}
