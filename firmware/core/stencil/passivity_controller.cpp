// The passivity observer's balance and the controller's damping.
#include "firmware/core/stencil/passivity_controller.hpp"

#include <cmath>

namespace stencil::engine {

double PassivityController::observe(const Eigen::Vector3d& held_force_n, const Eigen::Vector3d& displacement_m) {
  const double work_j = held_force_n.dot(displacement_m);
  if (std::isfinite(work_j)) {
    energy_j_ += work_j;
  }
  return energy_j_;
}

Eigen::Vector3d PassivityController::correction(const Eigen::Vector3d& velocity_m_per_s, double period_s,
                                                double max_force_n) const {
  const double speed_squared = velocity_m_per_s.squaredNorm();
  if (!(energy_j_ > 0.0) || !std::isfinite(speed_squared) || !(period_s > 0.0) || !(max_force_n > 0.0) ||
      speed_squared < kStillSpeedMPerS * kStillSpeedMPerS) {
    return Eigen::Vector3d::Zero();
  }
  const double alpha_n_s_per_m = std::fmin(energy_j_ / (period_s * speed_squared), kMaxDampingNSPerM);
  Eigen::Vector3d force = -alpha_n_s_per_m * velocity_m_per_s;
  const double magnitude = force.norm();
  if (magnitude > max_force_n) {
    force *= max_force_n / magnitude;
  }
  return force;
}

}  // namespace stencil::engine
