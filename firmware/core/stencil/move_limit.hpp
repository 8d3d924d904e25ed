// The one rule for how far a tip may move in one step: per axis, and all axes together (the mill
// steps one axis at a time, so |dx| + |dy| + |dz| is what its step rate bounds). Direction kept.
#pragma once

#include <Eigen/Core>

namespace stencil::engine {

// `to` when the move from `from` fits both bounds, else the point along it that just fits.
[[nodiscard]] inline Eigen::Vector3d shorten_move(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                                  double max_axis_mm, double max_total_mm, bool& shortened) {
  const Eigen::Vector3d move = to - from;
  const double largest = move.cwiseAbs().maxCoeff();
  const double total = move.cwiseAbs().sum();
  double scale = 1.0;
  if (largest > max_axis_mm) {
    scale = max_axis_mm / largest;
  }
  if (total * scale > max_total_mm) {
    scale = max_total_mm / total;
  }
  shortened = scale < 1.0;
  return shortened ? Eigen::Vector3d(from + scale * move) : to;
}

}  // namespace stencil::engine
