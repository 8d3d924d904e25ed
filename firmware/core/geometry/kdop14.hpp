// The 14-DOP bounding volume: seven fixed slab directions, an interval along each.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <span>

#include <Eigen/Core>

namespace stencil::geometry {

inline constexpr std::size_t kKdopSlabCount = 7;

// The slab directions, deliberately not normalised so that projecting is additions only:
// (1,0,0) (0,1,0) (0,0,1) (1,1,1) (1,-1,1) (1,1,-1) (1,-1,-1). Interval bounds are therefore in
// millimetres times the direction's length (1 or sqrt(3)).
inline constexpr std::array<std::array<double, 3>, kKdopSlabCount> kKdopSlabDirections = {{
    {1.0, 0.0, 0.0},
    {0.0, 1.0, 0.0},
    {0.0, 0.0, 1.0},
    {1.0, 1.0, 1.0},
    {1.0, -1.0, 1.0},
    {1.0, 1.0, -1.0},
    {1.0, -1.0, -1.0},
}};

// Length of each slab direction: the first three are unit axes, the diagonals have length sqrt(3).
inline constexpr std::array<double, kKdopSlabCount> kKdopSlabLength = {
    1.0, 1.0, 1.0, 1.7320508075688772, 1.7320508075688772, 1.7320508075688772, 1.7320508075688772};

// Projections of a point onto the seven slab directions (exact sums, no multiplications). Inline:
// the query's tool bound takes three at every query, the table generator one per point and level.
[[nodiscard]] inline std::array<double, kKdopSlabCount> kdop_projections(const Eigen::Vector3d& point_mm) {
  const double x = point_mm.x();
  const double y = point_mm.y();
  const double z = point_mm.z();
  return {x, y, z, x + y + z, x - y + z, x + y - z, x - y - z};
}

// The convex polytope { p : min[i] <= d_i . p <= max[i] for all seven directions d_i }.
// Plain data with no invariants beyond min <= max for a non-empty volume, so it can be stored in
// tables as-is. The empty volume has min = +inf, max = -inf on every slab.
struct Kdop14 {
  std::array<double, kKdopSlabCount> min;
  std::array<double, kKdopSlabCount> max;

  [[nodiscard]] static Kdop14 empty();
  [[nodiscard]] bool is_empty() const;

  // Grows the volume to include a point. Inline: the table generator's tree takes every point once
  // per level.
  void add(const Eigen::Vector3d& point_mm) {
    const auto projection = kdop_projections(point_mm);
    for (std::size_t slab = 0; slab < kKdopSlabCount; ++slab) {
      min[slab] = std::min(min[slab], projection[slab]);
      max[slab] = std::max(max[slab], projection[slab]);
    }
  }
  // Grows the volume to include another volume.
  void merge(const Kdop14& other);
  // The volume grown by margin_mm in every direction (each slab by margin_mm times its length),
  // so it contains every point within margin_mm of this one. A negative margin shrinks it.
  [[nodiscard]] Kdop14 enlarged(double margin_mm) const;
  // Whether the point lies inside every slab, each slab widened by tolerance_mm.
  [[nodiscard]] bool contains(const Eigen::Vector3d& point_mm, double tolerance_mm = 0.0) const;
};

static_assert(sizeof(Kdop14) == 2 * kKdopSlabCount * sizeof(double), "Kdop14 is stored in tables as-is");

// The tightest 14-DOP of a set of points (empty for no points).
[[nodiscard]] Kdop14 kdop_of_points(std::span<const Eigen::Vector3d> points_mm);

// The smallest 14-DOP holding both.
[[nodiscard]] Kdop14 merged(const Kdop14& a, const Kdop14& b);

// Seven interval tests with early out. Conservative: false means the volumes are certainly
// disjoint; true means no slab separates them (the polytopes may still miss each other along an
// edge-edge direction, which only costs the caller a closer look, never a missed contact).
[[nodiscard]] bool overlaps(const Kdop14& a, const Kdop14& b);

}  // namespace stencil::geometry
