// The shortest distance from a point to a part's surface (its triangles), and over a height field the
// signed distance from each cell's top to it: the stock picture's colours, as a CAM verification
// shows them. Triangles are bucketed over x-y so that a point looks only at those within reach.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/tables/part_tables.hpp"

namespace stencil::sim {

using Triangle = std::array<Eigen::Vector3d, 3>;

// The part's triangles as points in world mm.
[[nodiscard]] std::vector<Triangle> triangles_of(const tables::PartTables& part);

class SurfaceDistance {
 public:
  // Distances are exact up to `reach_mm` (> 0); a point farther from every triangle is reported as
  // reach_mm away. The buckets are reach_mm / 2 square: each holds every triangle within reach of it.
  SurfaceDistance(std::vector<Triangle> triangles, double reach_mm);

  // The shortest 3-D distance from `point` to any triangle, mm, at most reach_mm.
  [[nodiscard]] double distance(const Eigen::Vector3d& point) const;
  [[nodiscard]] double reach_mm() const { return reach_mm_; }

 private:
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Vector3d> box_low_, box_high_;  // each triangle's bounding box
  double reach_mm_;
  double bucket_mm_;
  Eigen::Vector2d origin_mm_ = Eigen::Vector2d::Zero();
  int columns_ = 0, rows_ = 0;
  std::vector<std::vector<std::uint32_t>> buckets_;  // row-major
};

// A height field's cells: `columns` x `rows` squares of `cell_mm` from `low_mm` (x, y), row-major.
struct CellGrid {
  int columns;
  int rows;
  double cell_mm;
  Eigen::Vector2d low_mm;
};

// Over each cell: the distance from its top point (the cell's centre at `heights`) to the part's
// surface, negative where that point is inside the part (below the part's top there,
// `part_heights`), clamped to +-surface.reach_mm(); row-major like the heights.
[[nodiscard]] std::vector<float> signed_distances(const SurfaceDistance& surface, const CellGrid& grid,
                                                  const std::vector<double>& heights,
                                                  const std::vector<double>& part_heights);

}  // namespace stencil::sim
