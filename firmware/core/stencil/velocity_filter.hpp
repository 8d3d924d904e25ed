// VelocityFilter: a velocity estimated from positions sampled once a period, as a real encoder's
// positions must be: the backward difference through a first-order low-pass.
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace stencil::engine {

// Why filtered: an encoder's positions are quantised (a count is a few micrometres on the rig's
// device), so the raw difference of two samples a millisecond apart jumps by a count's worth of
// speed from one period to the next, and damping rendered from it buzzes. The low-pass smooths
// that at the cost of lag (about 1 / (2 pi cutoff) seconds), and lag is what limits how much
// damping a sampled loop can render stably: 100 Hz is the usual compromise at 1 kHz. Real-time
// safe (no allocation, fixed work).
class VelocityFilter {
 public:
  static constexpr double kDefaultCutoffHz = 100.0;

  // `cutoff_hz` the corner of the low-pass, `period_s` the sampling period; a cutoff that is not
  // a positive number (or at or above the Nyquist rate, 1 / (2 period)) passes the raw difference.
  void configure(double cutoff_hz, double period_s) {
    period_s_ = period_s;
    const double omega_t = 2.0 * 3.14159265358979323846 * cutoff_hz * period_s;
    alpha_ = (std::isfinite(omega_t) && omega_t > 0.0 && cutoff_hz * period_s < 0.5) ? omega_t / (1.0 + omega_t) : 1.0;
  }

  // One sample: the estimate in position units per second. The first sample after a reset gives
  // zero (there is nothing to difference yet). `elapsed_s` is the time since the last sample when
  // it was not one period (a stale read in between); the filter's own step stays one period.
  const Eigen::Vector3d& update(const Eigen::Vector3d& position, double elapsed_s = 0.0) {
    const double dt = elapsed_s > 0.0 ? elapsed_s : period_s_;
    if (have_last_ && dt > 0.0) {
      const Eigen::Vector3d raw = (position - last_) / dt;
      value_ += alpha_ * (raw - value_);
    }
    last_ = position;
    have_last_ = true;
    return value_;
  }

  // Forget the history: after a gap in the samples, the next one starts again from zero.
  void reset() {
    have_last_ = false;
    value_.setZero();
  }

  [[nodiscard]] const Eigen::Vector3d& value() const { return value_; }
  [[nodiscard]] double alpha() const { return alpha_; }

 private:
  double period_s_ = 1e-3;
  double alpha_ = 1.0;
  bool have_last_ = false;
  Eigen::Vector3d last_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d value_ = Eigen::Vector3d::Zero();
};

}  // namespace stencil::engine
