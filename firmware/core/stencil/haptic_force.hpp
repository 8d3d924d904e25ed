// The force and torque the operator feels: the coupling to the virtual tool plus the contact force,
// clamped to the rig's safe limits, and never anything but finite numbers.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/speed_penalty.hpp"

namespace stencil::engine {

struct HapticLimits {
  double coupling_n_per_device_mm = 0.5;  // pull of the device towards the virtual tool
  double device_mm_per_world_mm = 10.0;
  double max_force_n = 5.0;               // the operator can always overpower it
  double max_torque_nmm = 200.0;
};

// How the wall feels beyond the coupling's spring (issue 29). All off by default: today's rendering,
// a spring to the virtual tool that slips along the part without sticking.
// How the virtual tool is kept to the speed the mill can follow: today's cap on its move per cycle
// alone, or with a penalty on the hand too (damping that rises as the hand nears that speed, the
// thesis's penalty-based speed limiting; the cap stays as the backstop).
enum class SpeedLimiting : std::uint8_t { Cap, Penalty };
[[nodiscard]] constexpr const char* speed_limiting_name(SpeedLimiting mode) {
  return mode == SpeedLimiting::Penalty ? "penalty" : "cap";
}

struct WallFeel {
  // Virtual damping on the coupling (N s per device metre): resists the rate at which the coupling
  // stretches or relaxes while the hand is in the wall; it may take the wall's push down to zero,
  // never into a pull towards the part.
  double damping_n_s_per_m = 0.0;
  // The passivity observer and controller (passivity_controller.hpp): damping only where the wall
  // has put out more energy than it took.
  bool passivity = false;
  // Coulomb friction of the virtual tool on the part (surface_friction.hpp), 0 to 1.
  double friction = 0.0;
  // The corner of the velocity estimate's low-pass (velocity_filter.hpp), Hz.
  double velocity_cutoff_hz = 100.0;
  // The device link's delay from command to motor (s): the passivity observer weighs the two last
  // commands by it for the force the device really held over the period.
  double transport_delay_s = 0.0;
  SpeedLimiting speed_limiting = SpeedLimiting::Cap;
  // Penalty: how steeply it rises with the hand's speed, N s per device metre (speed_penalty.hpp says
  // why this steep and no steeper).
  double speed_penalty_slope_n_s_per_m = kSpeedPenaltySlopeNSPerM;
};

struct HapticOutput {
  Eigen::Vector3d force_n;
  Eigen::Vector3d torque_nmm;
  bool clamped;  // the force or the torque hit its limit
  bool fault;    // an input was not finite: the output is zero
};

// force = coupling * (virtual - desired) in device millimetres + the contact force at the desired
// pose + `added_force_n` (the wall's damping, when the cycle renders it), clamped in magnitude to
// max_force_n; torque likewise to max_torque_nmm. A NaN or infinity anywhere gives zero force and
// torque and the fault flag. Real-time safe.
[[nodiscard]] HapticOutput haptic_output(const Eigen::Vector3d& desired_tip_mm, const Eigen::Vector3d& virtual_tip_mm,
                                         const ContactResult& contact_at_desired, const HapticLimits& limits,
                                         const Eigen::Vector3d& added_force_n = Eigen::Vector3d::Zero());

}  // namespace stencil::engine
