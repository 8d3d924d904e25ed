// The Sherline mill + Suzuki 5-DOF device rig: its physical constants (from the thesis, table 6-1).
#pragma once

namespace stencil::board::sherline_suzuki {

struct RigConstants {
  double workspace_mm[3];        // machine workspace, x y z: the box [0,X]x[0,Y]x[0,Z]
  double haptic_workspace_mm[3]; // the device's reach, x y z
  double haptic_to_machine_scale;  // device millimetres per machine millimetre
  double force_limit_n;          // the operator can always overpower this
  double steps_per_mm;           // motor resolution, every axis
  double max_speed_mm_per_s;     // per axis
  double backlash_mm[3];         // x y z
  double machine_update_hz;      // CY545 link at 57600 baud
  double haptic_rate_hz;         // the cycle
};

inline constexpr RigConstants kRig{
    {50.0, 25.0, 25.0},
    {500.0, 250.0, 250.0},
    10.0,
    5.0,
    640.0,
    1.4,
    {0.125, 0.05, 0.125},
    30.0,
    1000.0,
};

inline constexpr double largest_backlash_mm() {
  double largest = 0.0;
  for (const double backlash : kRig.backlash_mm) {
    largest = backlash > largest ? backlash : largest;
  }
  return largest;
}

}  // namespace stencil::board::sherline_suzuki
