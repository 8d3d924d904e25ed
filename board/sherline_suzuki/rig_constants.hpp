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

// ---- Axis travel, home switches and MMC-4S wiring (used by sim/mill and sim/cy545; the CY545 driver
// must use the same wiring). Machine coordinates per axis: 0 at the home switch's edge, + along the
// machine's + axis (X and Y: the table's own displacement, Z: the head's), workspace [0, workspace_mm].

// Axis index: x, y, z (the order of every per-axis array here).
inline constexpr int kAxisCount = 3;

// How far each axis can travel past the workspace: below 0 is the home switch's closed zone up to the
// low hard stop, above the workspace a margin up to the high hard stop.
inline constexpr double kHomeOvertravelMm = 3.0;
inline constexpr double kFarOvertravelMm = 5.0;

// The home switch is closed while the axis is below this machine coordinate (mm), open at and above it.
inline constexpr double kHomeSwitchEdgeMm = 0.0;

inline constexpr double travel_min_mm(int axis) {
  static_cast<void>(axis);
  return kHomeSwitchEdgeMm - kHomeOvertravelMm;
}
inline constexpr double travel_max_mm(int axis) { return kRig.workspace_mm[axis] + kFarOvertravelMm; }

// Millimetres to whole motor steps, rounded to nearest (every value used here is a whole number).
inline constexpr long long mm_to_steps(double mm) {
  const double steps = mm * kRig.steps_per_mm;
  return static_cast<long long>(steps < 0.0 ? steps - 0.5 : steps + 0.5);
}

// Backlash per axis in motor steps: 80, 32, 80.
inline constexpr long long backlash_steps(int axis) { return mm_to_steps(kRig.backlash_mm[axis]); }
static_assert(backlash_steps(0) == 80 && backlash_steps(1) == 32 && backlash_steps(2) == 80,
              "backlash must be a whole number of steps");

// MMC-4S multiplexer wiring: output-mux ports 0-3 select a motor channel, 4-7 are general-purpose
// latched outputs; input-mux ports 0-3 are the channels' home sensors, 4-7 general-purpose inputs.
struct Mmc4sWiring {
  int motor_channel[kAxisCount];      // output-mux port (= channel) of x y z
  int home_sensor_input[kAxisCount];  // input-mux port of the home switch of x y z
  int spindle_output;                 // general-purpose output port that runs the spindle (1 = on)
};
inline constexpr Mmc4sWiring kMmc4s{{0, 1, 2}, {0, 1, 2}, 4};

}  // namespace stencil::board::sherline_suzuki
