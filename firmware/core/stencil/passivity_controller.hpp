// PassivityController: the energy the rendered force has put into the hand, observed period by
// period, and the damping that takes back whatever the wall put out beyond what it took (the
// time-domain passivity observer and controller of Hannaford and Ryu, IEEE Transactions on
// Robotics and Automation 18(1), 2002).
#pragma once

#include <Eigen/Core>

namespace stencil::engine {

// Why: a wall rendered as a spring sampled once a millisecond and held between samples returns
// more energy than it took (the force lags the handle: it is still pushing out when the handle has
// already left), about k T / 2 of negative damping (Colgate and Schenkel 1997). A stiff coupling
// with a light grasp then buzzes or bounces. The observer adds up F . dx over each period (the work
// the held force did on the handle, positive into the hand); whenever that balance is positive the
// wall has put out energy it never took in, and the controller adds damping that dissipates it over
// the next period. Real-time safe: no allocation, fixed work.
class PassivityController {
 public:
  // Below this speed (m/s) no damping is added: the damping that would take the balance back in a
  // period grows as 1 / v^2, and one encoder count (1 um) a period is already 1e-3 m/s of noise.
  static constexpr double kStillSpeedMPerS = 2e-3;
  // The most damping it adds (N s/m): a few microjoules owed would otherwise be a kick at the force
  // limit the moment the handle moves; what is left is taken back over more periods.
  static constexpr double kMaxDampingNSPerM = 100.0;

  // One period: the force the device held over the period that just ended (N) and how far the
  // handle moved over it (m). Returns the balance (J): positive, the wall has put energy in.
  double observe(const Eigen::Vector3d& held_force_n, const Eigen::Vector3d& displacement_m);

  // The force to add this period (N): -alpha v with alpha = balance / (period |v|^2), which takes the
  // balance back if the handle keeps `velocity_m_per_s` over the next period; zero when the balance
  // is not positive, the handle is still, or an input is not finite. At most `max_force_n` in
  // magnitude (the rig's limit: the cycle clamps the sum again).
  [[nodiscard]] Eigen::Vector3d correction(const Eigen::Vector3d& velocity_m_per_s, double period_s,
                                           double max_force_n) const;

  // A contact starts, or the wall holds nothing and owes nothing: the balance starts again from zero,
  // so that one contact's excess is never paid for by what another (or dragging the lagging tool)
  // absorbed.
  void restart() { energy_j_ = 0.0; }
  // A contact starts: what the wall absorbed before it is forgotten, what it still owes is not.
  void forget_absorbed() { energy_j_ = energy_j_ > 0.0 ? energy_j_ : 0.0; }

  [[nodiscard]] double energy_j() const { return energy_j_; }

 private:
  double energy_j_ = 0.0;
};

}  // namespace stencil::engine
