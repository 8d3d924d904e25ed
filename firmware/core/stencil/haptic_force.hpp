// The force and torque the operator feels: the coupling to the virtual tool plus the contact force,
// clamped to the rig's safe limits, and never anything but finite numbers.
#pragma once

#include <Eigen/Core>

#include "firmware/core/stencil/contact_query.hpp"

namespace stencil::engine {

struct HapticLimits {
  double coupling_n_per_device_mm = 0.5;  // pull of the device towards the virtual tool
  double device_mm_per_world_mm = 10.0;
  double max_force_n = 5.0;               // the operator can always overpower it
  double max_torque_nmm = 200.0;
};

struct HapticOutput {
  Eigen::Vector3d force_n;
  Eigen::Vector3d torque_nmm;
  bool clamped;  // the force or the torque hit its limit
  bool fault;    // an input was not finite: the output is zero
};

// force = coupling * (virtual - desired) in device millimetres + the contact force at the desired
// pose, clamped in magnitude to max_force_n; torque likewise to max_torque_nmm. A NaN or infinity
// anywhere gives zero force and torque and the fault flag. Real-time safe.
[[nodiscard]] HapticOutput haptic_output(const Eigen::Vector3d& desired_tip_mm, const Eigen::Vector3d& virtual_tip_mm,
                                         const ContactResult& contact_at_desired, const HapticLimits& limits);

}  // namespace stencil::engine
