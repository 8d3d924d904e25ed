// The commanded stock: the tool's footprint pressed into a height field at points along each leg.
#include "firmware/core/control/commanded_stock.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::control {
namespace {

// The most cells along a side: 100 000 (5 m at 0.05 mm), so every count fits an int.
constexpr double kMaxCellsAlong = 100'000.0;

int cells_along(double low, double high, double cell) {
  return static_cast<int>(std::clamp(std::ceil((high - low) / cell - 1e-9), 0.0, kMaxCellsAlong));
}

// floor(v) as a cell index clamped to [low, high] in double first, so no cast overflows.
int index_clamped(double v, int low, int high) {
  return static_cast<int>(std::clamp(std::floor(v), static_cast<double>(low), static_cast<double>(high)));
}

}  // namespace

std::size_t CommandedStock::cells_needed(const StockBlock& block, double cell_mm) {
  if (!(cell_mm > 0.0) || !block.low_mm.allFinite() || !block.high_mm.allFinite() ||
      !(block.high_mm.array() > block.low_mm.array()).all() ||
      (block.high_mm.x() - block.low_mm.x()) / cell_mm > kMaxCellsAlong ||
      (block.high_mm.y() - block.low_mm.y()) / cell_mm > kMaxCellsAlong) {
    return 0;  // not a block, or too many cells to be one
  }
  return static_cast<std::size_t>(cells_along(block.low_mm.x(), block.high_mm.x(), cell_mm)) *
         static_cast<std::size_t>(cells_along(block.low_mm.y(), block.high_mm.y(), cell_mm));
}

CommandedStock::CommandedStock(const StockBlock& block, double cell_mm, const geometry::ToolSpec& tool,
                               std::span<float> cells)
    : block_(block), cell_mm_(cell_mm), tool_(tool), radius_mm_(0.5 * tool.diameter_mm), cells_(cells) {
  const std::size_t needed = cells_needed(block, cell_mm);
  if (needed == 0 || cells.size() < needed || !(radius_mm_ > 0.0)) {
    return;
  }
  columns_ = cells_along(block.low_mm.x(), block.high_mm.x(), cell_mm);
  rows_ = cells_along(block.low_mm.y(), block.high_mm.y(), cell_mm);
  std::fill(cells_.begin(), cells_.begin() + static_cast<std::ptrdiff_t>(needed), static_cast<float>(block.high_mm.z()));
  ready_ = true;
}

double CommandedStock::lift(double radial) const {
  switch (tool_.kind) {
    case geometry::CutterKind::Ball:
      return radius_mm_ - std::sqrt(std::max(0.0, radius_mm_ * radius_mm_ - radial * radial));
    case geometry::CutterKind::BullNose: {
      const double corner = std::clamp(tool_.corner_radius_mm, 0.0, radius_mm_);
      const double flat = radius_mm_ - corner;
      if (radial <= flat) {
        return 0.0;
      }
      const double off = radial - flat;
      return corner - std::sqrt(std::max(0.0, corner * corner - off * off));
    }
    case geometry::CutterKind::Flat:
      break;
  }
  return 0.0;
}

void CommandedStock::cut_at(const Eigen::Vector3d& tip) {
  const double x0 = block_.low_mm.x(), y0 = block_.low_mm.y();
  // Clamped to the block: a footprint wholly outside it gives an empty range (c0 > c1 or r0 > r1).
  const int c0 = index_clamped((tip.x() - radius_mm_ - x0) / cell_mm_, 0, columns_);
  const int c1 = index_clamped((tip.x() + radius_mm_ - x0) / cell_mm_, -1, columns_ - 1);
  const int r0 = index_clamped((tip.y() - radius_mm_ - y0) / cell_mm_, 0, rows_);
  const int r1 = index_clamped((tip.y() + radius_mm_ - y0) / cell_mm_, -1, rows_ - 1);
  for (int row = r0; row <= r1; ++row) {
    const double dy = y0 + (row + 0.5) * cell_mm_ - tip.y();
    for (int column = c0; column <= c1; ++column) {
      const double dx = x0 + (column + 0.5) * cell_mm_ - tip.x();
      const double radial = std::sqrt(dx * dx + dy * dy);
      if (radial > radius_mm_) {
        continue;
      }
      const double bottom = std::max(tip.z() + lift(radial), block_.low_mm.z());
      float& cell = cells_[static_cast<std::size_t>(row) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(column)];
      cell = std::min(cell, static_cast<float>(bottom));
    }
  }
}

void CommandedStock::cut(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  if (!ready_ || !from.allFinite() || !to.allFinite()) {
    return;
  }
  // Points a cell apart: between two, a ball's surface rises by r - sqrt(r^2 - (cell/2)^2), a
  // fraction of a micrometre. A leg that starts where the last ended has its first point cut.
  const double length = (to - from).norm();
  const int samples = static_cast<int>(std::clamp(std::ceil(length / cell_mm_), 1.0, static_cast<double>(kMaxSamples)));
  for (int i = (have_last_ && from == last_end_) ? 1 : 0; i <= samples; ++i) {
    cut_at(from + (static_cast<double>(i) / samples) * (to - from));
  }
  last_end_ = to;
  have_last_ = true;
}

double CommandedStock::height(int column, int row) const {
  if (!ready_ || column < 0 || row < 0 || column >= columns_ || row >= rows_) {
    return block_.high_mm.z();
  }
  return cells_[static_cast<std::size_t>(row) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(column)];
}

double CommandedStock::removed_volume_mm3() const {
  double removed = 0.0;
  for (int row = 0; row < rows_; ++row) {
    for (int column = 0; column < columns_; ++column) {
      removed += block_.high_mm.z() - height(column, row);
    }
  }
  return removed * cell_mm_ * cell_mm_;
}

}  // namespace stencil::control
