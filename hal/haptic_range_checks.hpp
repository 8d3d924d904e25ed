// The range rules of hal::HapticRange as functions: which samples are refused, how a command is
// clamped. Shared by both haptic backends. Real-time safe, header-only.
#pragma once

#include <cmath>
#include <cstdint>

#include "hal/haptic_device.hpp"

namespace stencil::hal {

// True when every position and angle is a finite number.
[[nodiscard]] inline bool sample_finite(const HapticSample& sample) {
  for (const double v : sample.position_mm) {
    if (!std::isfinite(v)) return false;
  }
  for (const double v : sample.angles_rad) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// True when every position and angle is finite and within the range.
[[nodiscard]] inline bool sample_in_range(const HapticSample& sample, const HapticRange& range) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!(std::fabs(sample.position_mm[axis] - range.position_centre_mm[axis]) <= range.position_limit_mm[axis])) {
      return false;
    }
  }
  for (const double angle : sample.angles_rad) {
    if (!(std::fabs(angle) <= range.angle_limit_rad)) return false;
  }
  return true;
}

struct ClampedCommand {
  double force_n[3];
  double torque_nmm[2];
  bool finite;   // false: every value is zero and the command must go out with enable off
  bool clamped;  // the force or the torque was scaled down to its limit
};

// Scales force and torque down (direction kept) to at most the given magnitudes; a command with any
// NaN or infinity becomes all zero with finite == false.
[[nodiscard]] inline ClampedCommand clamp_command(const HapticCommand& command, double force_limit_n,
                                                  double torque_limit_nmm) {
  ClampedCommand out{{0.0, 0.0, 0.0}, {0.0, 0.0}, true, false};
  for (const double value : command.force_n) out.finite = out.finite && std::isfinite(value);
  for (const double value : command.torque_nmm) out.finite = out.finite && std::isfinite(value);
  if (!out.finite) return out;

  const double force_norm = std::sqrt(command.force_n[0] * command.force_n[0] +
                                      command.force_n[1] * command.force_n[1] +
                                      command.force_n[2] * command.force_n[2]);
  const double force_scale = force_norm > force_limit_n ? force_limit_n / force_norm : 1.0;
  const double torque_norm = std::sqrt(command.torque_nmm[0] * command.torque_nmm[0] +
                                       command.torque_nmm[1] * command.torque_nmm[1]);
  const double torque_scale = torque_norm > torque_limit_nmm ? torque_limit_nmm / torque_norm : 1.0;
  // A sum of squares of finite values can still overflow to infinity: then the scale is zero.
  for (int axis = 0; axis < 3; ++axis) out.force_n[axis] = command.force_n[axis] * force_scale;
  for (int axis = 0; axis < 2; ++axis) out.torque_nmm[axis] = command.torque_nmm[axis] * torque_scale;
  out.clamped = force_scale < 1.0 || torque_scale < 1.0;
  return out;
}

// What a write that went out reports, counted: refused (not finite: zero force, enable off was
// sent instead), clamped, or as given. Shared by both backends.
[[nodiscard]] inline WriteResult write_outcome(const ClampedCommand& clamped, HapticCounters& counters) {
  if (!clamped.finite) {
    ++counters.commands_rejected;
    return {WriteStatus::Rejected, HapticFault::CommandNotFinite};
  }
  if (clamped.clamped) {
    ++counters.commands_clamped;
    return {WriteStatus::Clamped, HapticFault::None};
  }
  return {WriteStatus::Written, HapticFault::None};
}

// A clamped value in physical units times `units_per_value` (1000: N to mN), rounded toward zero so
// a clamped magnitude never grows past its limit; the caller guarantees the product fits in int32.
[[nodiscard]] inline std::int32_t to_units_toward_zero(double value, double units_per_value) {
  return static_cast<std::int32_t>(value * units_per_value);
}

}  // namespace stencil::hal
