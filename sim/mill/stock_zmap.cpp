// Z-map cuts along single-axis moves.
#include "sim/mill/stock_zmap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stencil::sim {

ToolProfile ToolProfile::of(const geometry::ToolSpec& spec) {
  return {spec.kind, spec.diameter_mm / 2.0, spec.kind == geometry::CutterKind::BullNose ? spec.corner_radius_mm : 0.0};
}

double ToolProfile::height_at(double distance_mm) const {
  if (!(distance_mm <= radius_mm)) {
    return std::numeric_limits<double>::infinity();
  }
  switch (kind) {
    case geometry::CutterKind::Flat:
      return 0.0;
    case geometry::CutterKind::Ball:
      return radius_mm - std::sqrt(std::max(0.0, radius_mm * radius_mm - distance_mm * distance_mm));
    case geometry::CutterKind::BullNose: {
      const double flat = radius_mm - corner_radius_mm;
      if (distance_mm <= flat) {
        return 0.0;
      }
      const double d = distance_mm - flat;
      return corner_radius_mm - std::sqrt(std::max(0.0, corner_radius_mm * corner_radius_mm - d * d));
    }
  }
  return 0.0;
}

StockZmap::StockZmap(const StockBox& box, double max_cell_mm) : box_(box) {
  const double width = box.high_mm.x() - box.low_mm.x();
  const double depth = box.high_mm.y() - box.low_mm.y();
  columns_ = std::max(1, static_cast<int>(std::ceil(width / max_cell_mm)));
  rows_ = std::max(1, static_cast<int>(std::ceil(depth / max_cell_mm)));
  // Square cells no larger than asked: the larger of the two axes' sizes.
  cell_ = std::max(width / columns_, depth / rows_);
  heights_.assign(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_), box.high_mm.z());
}

Eigen::Vector2d StockZmap::centre(int column, int row) const {
  return {box_.low_mm.x() + (column + 0.5) * cell_, box_.low_mm.y() + (row + 0.5) * cell_};
}

void StockZmap::cut(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const ToolProfile& tool) {
  // The staircase x, y, z: each leg along one axis.
  Eigen::Vector3d at = from;
  for (int axis = 0; axis < 3; ++axis) {
    if (to[axis] == at[axis]) {
      continue;
    }
    Eigen::Vector3d next = at;
    next[axis] = to[axis];
    cut_horizontal(at, next, tool);
    at = next;
  }
  if (from == to) {
    cut_horizontal(from, to, tool);
  }
}

// One leg: either horizontal at one height, or vertical (the lowest point of it is what cuts). For
// a cell, the tool's surface over it is lowest where the axis passes nearest: the segment of tip
// positions' point nearest the cell's centre.
void StockZmap::cut_horizontal(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const ToolProfile& tool) {
  const double z = std::min(from.z(), to.z());
  if (z >= box_.high_mm.z()) {
    return;  // entirely above the stock
  }
  const Eigen::Vector2d a(from.x(), from.y()), b(to.x(), to.y());
  const double reach = tool.radius_mm;
  const int c0 = std::max(0, static_cast<int>(std::floor((std::min(a.x(), b.x()) - reach - box_.low_mm.x()) / cell_)));
  const int c1 = std::min(columns_ - 1, static_cast<int>(std::floor((std::max(a.x(), b.x()) + reach - box_.low_mm.x()) / cell_)));
  const int r0 = std::max(0, static_cast<int>(std::floor((std::min(a.y(), b.y()) - reach - box_.low_mm.y()) / cell_)));
  const int r1 = std::min(rows_ - 1, static_cast<int>(std::floor((std::max(a.y(), b.y()) + reach - box_.low_mm.y()) / cell_)));
  const Eigen::Vector2d along = b - a;
  const double length_squared = along.squaredNorm();
  for (int row = r0; row <= r1; ++row) {
    for (int column = c0; column <= c1; ++column) {
      const Eigen::Vector2d p = centre(column, row);
      const double t = length_squared > 0.0 ? std::clamp((p - a).dot(along) / length_squared, 0.0, 1.0) : 0.0;
      const double surface = z + tool.height_at((p - (a + t * along)).norm());
      double& height = heights_[index(column, row)];
      height = std::max(box_.low_mm.z(), std::min(height, surface));
    }
  }
}

double StockZmap::removed_volume_mm3() const {
  double removed = 0.0;
  for (const double height : heights_) {
    removed += box_.high_mm.z() - height;
  }
  return removed * cell_ * cell_;
}

}  // namespace stencil::sim
