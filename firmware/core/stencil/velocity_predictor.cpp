// A free nominal mass driven by the committed forces' changes, seen through the same filter as the
// handle: the part of its velocity the filter has not shown yet is the prediction.
#include "firmware/core/stencil/velocity_predictor.hpp"

#include <algorithm>
#include <cmath>

namespace stencil::engine {

void VelocityPredictor::configure(double filter_alpha, double period_s, double transport_delay_s,
                                  double nominal_mass_kg, double balance_cutoff_hz) {
  const bool usable = std::isfinite(filter_alpha) && filter_alpha > 0.0 && std::isfinite(period_s) && period_s > 0.0 &&
                      std::isfinite(nominal_mass_kg) && nominal_mass_kg > 0.0 && std::isfinite(balance_cutoff_hz) &&
                      balance_cutoff_hz > 0.0;
  filter_alpha_ = usable ? std::min(filter_alpha, 1.0) : 1.0;
  period_s_ = usable ? period_s : 1e-3;
  delay_s_ = std::isfinite(transport_delay_s) ? std::clamp(transport_delay_s, 0.0, period_s_) : 0.0;
  inverse_mass_ = usable ? 1.0 / nominal_mass_kg : 0.0;
  const double omega_t = 2.0 * 3.14159265358979323846 * balance_cutoff_hz * period_s_;
  balance_alpha_ = usable ? omega_t / (1.0 + omega_t) : 0.0;
  reset();
}

void VelocityPredictor::sample(double elapsed_s) {
  const double dt = elapsed_s > 0.0 ? elapsed_s : period_s_;
  // The filter's view of the model moves on by one raw difference (its displacement over the time
  // since); the reference velocity moves to the model's own velocity now.
  filtered_lag_ = (filtered_lag_ - velocity_since_) + filter_alpha_ * (displacement_since_ / dt - filtered_lag_);
  velocity_since_.setZero();
  displacement_since_.setZero();
}

Eigen::Vector3d VelocityPredictor::predict(const Eigen::Vector3d& filtered_m_per_s) const {
  // The model's velocity when this cycle's force takes over (the last force still acts for the
  // link's delay) less what the filter shows of it.
  return filtered_m_per_s + velocity_since_ + delay_s_ * inverse_mass_ * force_before_ - filtered_lag_;
}

void VelocityPredictor::commit(const Eigen::Vector3d& force_n) {
  if (!force_n.allFinite()) {
    return;  // the cycle's own checks stop it; the model keeps what it had
  }
  balance_ += balance_alpha_ * (force_n - balance_);
  const Eigen::Vector3d change = force_n - balance_;
  // Over the coming period the last force acts for the delay, this one for the rest.
  const double rest_s = period_s_ - delay_s_;
  const Eigen::Vector3d displacement =
      inverse_mass_ * (force_before_ * (0.5 * delay_s_ * delay_s_ + delay_s_ * rest_s) + change * (0.5 * rest_s * rest_s));
  displacement_since_ += velocity_since_ * period_s_ + displacement;
  velocity_since_ += inverse_mass_ * (force_before_ * delay_s_ + change * rest_s);
  force_before_ = change;
}

void VelocityPredictor::reset() {
  filtered_lag_.setZero();
  velocity_since_.setZero();
  displacement_since_.setZero();
  force_before_.setZero();
  balance_.setZero();
}

}  // namespace stencil::engine
