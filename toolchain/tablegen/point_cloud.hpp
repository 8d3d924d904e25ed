// The part's point cloud: vertices, centroids, and samples that cover the surface to radius h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/geometry/tool_spec.hpp"
#include "toolchain/tablegen/part_mesh.hpp"

namespace stencil::tablegen {

struct CloudPoint {
  Eigen::Vector3d position_mm;
  Eigen::Vector3d normal;  // unit, of the point's triangle
  std::uint32_t triangle;
};

struct CloudOptions {
  double covering_radius_mm;     // h: no surface point farther than this from a sample
  std::uint64_t extra_points = 0;
  std::uint64_t seed = 1;
  double allowance_mm = 0.0;     // every point moved out along its normal by this
  unsigned threads = 1;
};

struct PointCloud {
  std::vector<CloudPoint> points;
  std::size_t vertex_points = 0;
  double achieved_covering_radius_mm = 0.0;  // the largest piece's covering radius (<= h)
};

// Deepest the tool can dip into the true surface between samples spaced to covering radius h:
// the lowest rounded edge's sagitta, r - sqrt(r^2 - h^2), where r is the ball radius (ball end)
// or the corner radius (bull-nose); h itself for a flat end mill's sharp corner.
[[nodiscard]] double gouge_bound_mm(const geometry::ToolSpec& tool, double covering_radius_mm);

// The largest h whose gouge bound is at most max_gouge_mm (the inverse of gouge_bound_mm).
[[nodiscard]] double covering_radius_for_gouge(const geometry::ToolSpec& tool, double max_gouge_mm);

// How many points build_point_cloud would make (without making them): for the capacity check.
[[nodiscard]] std::uint64_t count_cloud_points(const PartMesh& mesh, const CloudOptions& options);

// Every distinct vertex (with its lowest-numbered triangle's normal), every centroid, then each
// triangle cut into k x k similar pieces with k = ceil(c / h), c the triangle's covering radius
// (circumradius, or half the longest edge when obtuse), keeping the pieces' vertices that are not
// the triangle's own; then `extra_points` seeded area-weighted random points. Every point of a
// triangle lies in a piece and so within c / k <= h of a kept point. Points on an edge shared by
// two triangles are kept by both. The result does not depend on `threads`.
[[nodiscard]] PointCloud build_point_cloud(const PartMesh& mesh, const CloudOptions& options,
                                           const std::function<void(double)>& progress);

}  // namespace stencil::tablegen
