// CommandedStock: the controller's own model of the machined stock, a Z-map cut by the tool along
// every leg the machine side commanded. Owned by the machine side; resume and the display read it.
// It knows only what was sent, not what the mill did (backlash, lost steps): the simulated mill's
// Z-map is the ground truth and stays apart from it.
// Allocation-free: the cells are the caller's, sized by cells_needed() once, before the job.
#pragma once

#include <cstddef>
#include <span>

#include <Eigen/Core>

#include "firmware/core/geometry/tool_spec.hpp"

namespace stencil::control {

struct StockBlock {
  Eigen::Vector3d low_mm, high_mm;  // world; the material fills it at the start
};

class CommandedStock {
 public:
  // The cells of a Z-map of `block` at most `cell_mm` apart.
  [[nodiscard]] static std::size_t cells_needed(const StockBlock& block, double cell_mm);

  // `cells` must hold cells_needed(block, cell_mm) floats; ready() says whether it did (and whether
  // the block and the tool made sense).
  CommandedStock(const StockBlock& block, double cell_mm, const geometry::ToolSpec& tool, std::span<float> cells);

  [[nodiscard]] bool ready() const { return ready_; }

  // The tool's tip went straight from `from` to `to` (world mm): cut everything its cutter passed.
  // The work is bounded by the block's cells: a leg is cut at most kMaxSamples times along its
  // length (a longer leg is cut at coarser steps, never skipped).
  void cut(const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm);

  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] double cell_mm() const { return cell_mm_; }
  [[nodiscard]] const StockBlock& block() const { return block_; }
  // The stock's height over cell (column, row), world mm.
  [[nodiscard]] double height(int column, int row) const;
  [[nodiscard]] double removed_volume_mm3() const;

  static constexpr int kMaxSamples = 4096;

 private:
  // How far above the tip the cutter's lower surface is at `radial` mm off the axis (radial <= R).
  [[nodiscard]] double lift(double radial) const;
  void cut_at(const Eigen::Vector3d& tip_mm);

  StockBlock block_;
  double cell_mm_ = 0.0;
  geometry::ToolSpec tool_{};
  double radius_mm_ = 0.0;
  std::span<float> cells_;
  Eigen::Vector3d last_end_ = Eigen::Vector3d::Zero();
  bool have_last_ = false;
  int columns_ = 0, rows_ = 0;
  bool ready_ = false;
};

}  // namespace stencil::control
