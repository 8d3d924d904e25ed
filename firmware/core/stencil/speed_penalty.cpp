// The speed penalty's law: a damper with a bounded slope, from an onset below the mill's speed to the
// force limit.
#include "firmware/core/stencil/speed_penalty.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stencil::engine {

double mill_speed_along(const Eigen::Vector3d& direction, double axis_speed, double total_speed) {
  constexpr double kUnbounded = std::numeric_limits<double>::infinity();
  const double length = direction.norm();
  if (!(length > 0.0) || !std::isfinite(length)) {
    return kUnbounded;
  }
  const Eigen::Vector3d unit = direction.cwiseAbs() / length;
  // At speed s along `unit` the largest axis moves at s max|u_i| and all together at s sum|u_i|.
  return std::min(axis_speed / unit.maxCoeff(), total_speed / unit.sum());
}

Eigen::Vector3d speed_penalty_n(const Eigen::Vector3d& velocity_m_per_s, double limit_m_per_s, double max_force_n,
                                double slope_n_s_per_m, double onset_fraction) {
  const double speed = velocity_m_per_s.norm();
  if (!std::isfinite(speed) || !(speed > 0.0) || !std::isfinite(limit_m_per_s) || !(limit_m_per_s > 0.0) ||
      !std::isfinite(max_force_n) || !(max_force_n > 0.0) || !std::isfinite(slope_n_s_per_m) ||
      !(slope_n_s_per_m > 0.0) || !std::isfinite(onset_fraction)) {
    return Eigen::Vector3d::Zero();
  }
  // As late as still reaches the force limit at the speed limit, and never before the fraction.
  const double onset =
      std::max(std::clamp(onset_fraction, 0.0, 1.0) * limit_m_per_s, limit_m_per_s - max_force_n / slope_n_s_per_m);
  const double penalty = std::clamp(slope_n_s_per_m * (speed - onset), 0.0, max_force_n);
  return (-penalty / speed) * velocity_m_per_s;
}

}  // namespace stencil::engine
