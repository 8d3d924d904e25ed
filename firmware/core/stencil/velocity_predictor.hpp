// VelocityPredictor: the handle's velocity as it is now rather than as the velocity filter last saw
// it: the filtered estimate plus what the cycle's own recent forces have done to a free mass since
// (a Smith predictor on a nominal mass), so that a damper rendered from it damps the present.
#pragma once

#include <Eigen/Core>

namespace stencil::engine {

// Why: the filtered velocity (velocity_filter.hpp) lags the handle by about 2.8 ms at 1 kHz: the
// low-pass's 1.6 ms, half a period of backward difference, and the link's delay before the motors
// take the command (0.7 ms over CAN). A damper b rendered from it on a mass m rings, and goes unstable
// once b T / m nears 1, well before the 2 of an ideal sampled damper: through the cycle with the
// simulated hands over CAN, the lightest grasp (0.3 kg) is unstable by 300 N s/m, and a handle let go
// (0.2 kg alone) buzzes at the force limit at 400 (speed_penalty.hpp has the figures). The cycle
// knows the force it commanded: on a free mass of the nominal mass those forces have changed the
// velocity by their impulse over the mass, part of which the filter has not shown yet; adding that
// part back takes the lag out of the damper's own loop, and the same grasps and the released handle
// stay stable to twice the slope. Only the force's changes count (it is high-passed at
// kBalanceCutoffHz): a steady force is the hand's push balanced, and a free mass would predict a
// slowing that never comes. The nominal mass is the lightest grasp's; measured with the grasps of
// 0.3 to 0.7 kg and the bare handle's 0.2 kg. Real-time safe: fixed work, no allocation.
class VelocityPredictor {
 public:
  static constexpr double kNominalMassKg = 0.3;     // the device (0.2 kg) and the lightest grasp's arm
  static constexpr double kBalanceCutoffHz = 10.0;  // below this a force is taken as balanced by the hand

  // `filter_alpha` the velocity filter's own (VelocityFilter::alpha()), `period_s` the cycle's,
  // `transport_delay_s` the link's from command to motor (taken within [0, period_s]). A mass or a
  // cutoff that is not a positive number predicts nothing (predict() gives the estimate back).
  void configure(double filter_alpha, double period_s, double transport_delay_s,
                 double nominal_mass_kg = kNominalMassKg, double balance_cutoff_hz = kBalanceCutoffHz);

  // A fresh sample, taken by the velocity filter at the same moment: `elapsed_s` since the last one
  // (0: one period), as the filter was given it.
  void sample(double elapsed_s = 0.0);

  // The velocity when this cycle's force starts to act (m/s): `filtered_m_per_s` (the filter's
  // estimate) plus what the forces committed so far did to the nominal mass that the estimate does not
  // show yet.
  [[nodiscard]] Eigen::Vector3d predict(const Eigen::Vector3d& filtered_m_per_s) const;

  // The force this cycle commands (N): acting from the link's delay after now, for a period.
  void commit(const Eigen::Vector3d& force_n);

  // Forget everything, as the filter does after a gap in the samples.
  void reset();

 private:
  double filter_alpha_ = 1.0;
  double period_s_ = 1e-3;
  double delay_s_ = 0.0;
  double inverse_mass_ = 0.0;   // 0: predicts nothing
  double balance_alpha_ = 0.0;
  // The model's state, per axis, relative to its own velocity at the last sample: what the filter
  // would show of it (minus that velocity), and its velocity and displacement since (m/s, m).
  Eigen::Vector3d filtered_lag_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_since_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d displacement_since_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_before_ = Eigen::Vector3d::Zero();  // last committed, its changes only (N)
  Eigen::Vector3d balance_ = Eigen::Vector3d::Zero();       // the force's slow part (N)
};

}  // namespace stencil::engine
