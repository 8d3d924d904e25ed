// Distances to the part's surface through x-y buckets of its triangles.
#include "sim/mill/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "sim/mill/triangle_distance.hpp"

namespace stencil::sim {
namespace {

// At most about this many buckets along an axis, whatever the part's size against the reach.
constexpr double kMostBucketsAcross = 1024.0;

}  // namespace

std::vector<Triangle> triangles_of(const tables::PartTables& part) {
  std::vector<Triangle> triangles;
  triangles.reserve(part.triangle_count());
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    Triangle triangle;
    for (std::size_t i = 0; i < 3; ++i) {
      const tables::PackedPoint& v = part.triangles[t].vertices[i];
      triangle[i] = {static_cast<double>(v.x_mm), static_cast<double>(v.y_mm), static_cast<double>(v.z_mm)};
    }
    triangles.push_back(triangle);
  }
  return triangles;
}

SurfaceDistance::SurfaceDistance(std::vector<Triangle> triangles, double reach_mm)
    : triangles_(std::move(triangles)), reach_mm_(reach_mm), bucket_mm_(reach_mm / 2.0) {
  if (triangles_.empty()) {
    return;  // no buckets: every point is out of reach
  }
  Eigen::Vector2d low = Eigen::Vector2d::Constant(HUGE_VAL), high = Eigen::Vector2d::Constant(-HUGE_VAL);
  for (const Triangle& t : triangles_) {
    box_low_.push_back(t[0].cwiseMin(t[1]).cwiseMin(t[2]));
    box_high_.push_back(t[0].cwiseMax(t[1]).cwiseMax(t[2]));
    low = low.cwiseMin(box_low_.back().head<2>());
    high = high.cwiseMax(box_high_.back().head<2>());
  }
  // A point farther than the reach outside every triangle's box needs no bucket.
  origin_mm_ = low.array() - reach_mm_;
  const Eigen::Vector2d extent = (high - low).array() + 2.0 * reach_mm_;
  bucket_mm_ = std::max(bucket_mm_, extent.maxCoeff() / kMostBucketsAcross);
  columns_ = static_cast<int>(std::ceil(extent.x() / bucket_mm_));
  rows_ = static_cast<int>(std::ceil(extent.y() / bucket_mm_));
  buckets_.resize(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_));
  // A triangle within reach of a point has its box, grown by the reach, over that point's bucket.
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto first = [&](double mm, double origin, int count) {
      return std::clamp(static_cast<int>(std::floor((mm - reach_mm_ - origin) / bucket_mm_)), 0, count - 1);
    };
    const auto last = [&](double mm, double origin, int count) {
      return std::clamp(static_cast<int>(std::floor((mm + reach_mm_ - origin) / bucket_mm_)), 0, count - 1);
    };
    for (int row = first(box_low_[t].y(), origin_mm_.y(), rows_); row <= last(box_high_[t].y(), origin_mm_.y(), rows_); ++row) {
      for (int column = first(box_low_[t].x(), origin_mm_.x(), columns_);
           column <= last(box_high_[t].x(), origin_mm_.x(), columns_); ++column) {
        buckets_[static_cast<std::size_t>(row) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(column)]
            .push_back(static_cast<std::uint32_t>(t));
      }
    }
  }
}

double SurfaceDistance::distance(const Eigen::Vector3d& point) const {
  const double column = std::floor((point.x() - origin_mm_.x()) / bucket_mm_);
  const double row = std::floor((point.y() - origin_mm_.y()) / bucket_mm_);
  if (buckets_.empty() || column < 0.0 || row < 0.0 || column >= columns_ || row >= rows_) {
    return reach_mm_;
  }
  double best = reach_mm_;
  for (const std::uint32_t t : buckets_[static_cast<std::size_t>(row) * static_cast<std::size_t>(columns_) +
                                        static_cast<std::size_t>(column)]) {
    // The box is never farther than the triangle: skip those that cannot beat the best so far.
    const Eigen::Vector3d nearest_in_box = point.cwiseMax(box_low_[t]).cwiseMin(box_high_[t]);
    if ((nearest_in_box - point).squaredNorm() >= best * best) {
      continue;
    }
    const Triangle& triangle = triangles_[t];
    best = std::min(best, (closest_on_triangle(point, triangle[0], triangle[1], triangle[2]) - point).norm());
  }
  return best;
}

std::vector<float> signed_distances(const SurfaceDistance& surface, const CellGrid& grid,
                                    const std::vector<double>& heights, const std::vector<double>& part_heights) {
  std::vector<float> distances(heights.size(), 0.0F);
  for (int row = 0; row < grid.rows; ++row) {
    for (int column = 0; column < grid.columns; ++column) {
      const std::size_t i = static_cast<std::size_t>(row) * static_cast<std::size_t>(grid.columns) + static_cast<std::size_t>(column);
      const Eigen::Vector3d top(grid.low_mm.x() + (column + 0.5) * grid.cell_mm,
                                grid.low_mm.y() + (row + 0.5) * grid.cell_mm, heights[i]);
      const double distance = surface.distance(top);
      // A height field's top point is inside the part where it is below the part's top there.
      distances[i] = static_cast<float>(heights[i] < part_heights[i] ? -distance : distance);
    }
  }
  return distances;
}

}  // namespace stencil::sim
