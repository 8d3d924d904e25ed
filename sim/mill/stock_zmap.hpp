// The stock as a Z-map: a grid of cells (at most 0.05 mm) over the stock's footprint, each holding
// the height of material left above it. The simulated mill's tool takes material away along each
// single-axis move it makes; the Z-map gives the removed, left and gouged volumes and the picture.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::sim {

// The tool's lower envelope: how far above the tip the cutter's surface is at a distance from the
// axis (mm); +infinity beyond the cutter's radius (the shank and holder are not modelled here).
struct ToolProfile {
  geometry::CutterKind kind;
  double radius_mm;
  double corner_radius_mm;  // bull-nose only

  [[nodiscard]] static ToolProfile of(const geometry::ToolSpec& spec);
  [[nodiscard]] double height_at(double distance_mm) const;
};

// The stock box [low, high] (mm, world).
struct StockBox {
  Eigen::Vector3d low_mm;
  Eigen::Vector3d high_mm;
};

class StockZmap {
 public:
  // Cells of at most max_cell_mm (square); every cell starts full, at the stock's top.
  StockZmap(const StockBox& box, double max_cell_mm);

  // The tool's tip moved in a straight line along one axis from `from` to `to` (world mm): every
  // cell under the swept tool is cut down to the tool's lowest surface over it. A move along
  // several axes at once is cut as the staircase x, y, z.
  void cut(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const ToolProfile& tool);

  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] double cell_mm() const { return cell_; }
  [[nodiscard]] const StockBox& box() const { return box_; }
  [[nodiscard]] double height(int column, int row) const { return heights_[index(column, row)]; }
  [[nodiscard]] Eigen::Vector2d centre(int column, int row) const;
  [[nodiscard]] double removed_volume_mm3() const;

 private:
  [[nodiscard]] std::size_t index(int column, int row) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(column);
  }
  void cut_horizontal(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const ToolProfile& tool);

  StockBox box_;
  double cell_;
  int columns_;
  int rows_;
  std::vector<double> heights_;
};

}  // namespace stencil::sim
