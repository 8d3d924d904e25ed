// Coupling plus contact, clamped; NaN in, zero out.
#include "firmware/core/stencil/haptic_force.hpp"

#include <cmath>

namespace stencil::engine {
namespace {

bool clamp_magnitude(Eigen::Vector3d& vector, double limit) {
  const double magnitude = vector.norm();
  if (magnitude > limit) {
    vector *= limit / magnitude;
    return true;
  }
  return false;
}

}  // namespace

HapticOutput haptic_output(const Eigen::Vector3d& desired_tip_mm, const Eigen::Vector3d& virtual_tip_mm,
                           const ContactResult& contact_at_desired, const HapticLimits& limits,
                           const Eigen::Vector3d& added_force_n) {
  const bool inputs_finite = desired_tip_mm.allFinite() && virtual_tip_mm.allFinite() && added_force_n.allFinite() &&
                             contact_at_desired.force_n.allFinite() && contact_at_desired.torque_nmm.allFinite() &&
                             std::isfinite(limits.coupling_n_per_device_mm) && std::isfinite(limits.max_force_n) &&
                             std::isfinite(limits.max_torque_nmm) && std::isfinite(limits.device_mm_per_world_mm);
  if (!inputs_finite || contact_at_desired.status != QueryStatus::Ok) {
    return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false, true};
  }
  Eigen::Vector3d force = limits.coupling_n_per_device_mm * limits.device_mm_per_world_mm *
                              (virtual_tip_mm - desired_tip_mm) +
                          contact_at_desired.force_n;
  if ((added_force_n.array() != 0.0).any()) {
    force += added_force_n;  // only then: adding zeros would turn a -0.0 into +0.0 in today's rendering
  }
  Eigen::Vector3d torque = contact_at_desired.torque_nmm;
  bool clamped = clamp_magnitude(force, limits.max_force_n);
  clamped = clamp_magnitude(torque, limits.max_torque_nmm) || clamped;
  if (!force.allFinite() || !torque.allFinite()) {
    return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false, true};
  }
  return {force, torque, clamped, false};
}

}  // namespace stencil::engine
