// The Sherline mill + Suzuki 5-DOF device rig: every fact of it, once (the thesis, table 6-1, and the
// wiring of its MMC-4S board), and what follows from them. Nothing else types these numbers: the rig's
// job and program take them from here, board/sim derives the simulation's from them, and sim/, hal/
// and the table generator are handed what they need as parameters.
#pragma once

#include <array>
#include <cstdint>

#include "firmware/core/motion/machine_planner.hpp"
#include "hal/clock.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/haptic_device.hpp"
#include "hal/linuxcnc/linuxcnc_link.hpp"

namespace stencil::board::sherline_suzuki {

// What drives the mill's motors.
enum class MachineController : std::uint8_t {
  Cy545,     // the CY545 on the MMC-4S board over RS-232 (hal/cy545): the thesis's rig, 30 updates a second
  Linuxcnc,  // LinuxCNC through linuxcncrsh over TCP (hal/linuxcnc): one G1 an update, about 8 a second
};

// A mill driven by LinuxCNC: how to reach linuxcncrsh, and each axis's limits as LinuxCNC's INI gives
// them (its [AXIS_X|Y|Z] and [TRAJ] sections, read when the configuration is loaded: linuxcnc_ini.hpp).
// LinuxCNC plans and paces every move itself within these; planner_limits() spends them.
struct LinuxcncFacts {
  std::array<char, 16> address;                       // IPv4 digits, NUL-terminated
  std::uint16_t port;                                 // linuxcncrsh --port
  std::array<char, 32> connect_password;              // linuxcncrsh --connectpw, NUL-terminated (at most 15)
  std::array<char, 32> enable_password;               // linuxcncrsh --enablepw
  std::array<double, 3> max_velocity_mm_per_s;        // [AXIS_X|Y|Z] MAX_VELOCITY
  std::array<double, 3> max_acceleration_mm_per_s2;   // [AXIS_X|Y|Z] MAX_ACCELERATION
  double max_linear_velocity_mm_per_s;                // [TRAJ] MAX_LINEAR_VELOCITY; 0: the INI gives none

  bool operator==(const LinuxcncFacts&) const = default;
};

// A NUL-terminated fixed array from a literal (constexpr: the compiled-in facts hold text this way).
template <std::size_t N>
constexpr std::array<char, N> fixed_text(const char* text) {
  std::array<char, N> out{};
  for (std::size_t i = 0; i + 1 < N && text[i] != '\0'; ++i) {
    out[i] = text[i];
  }
  return out;
}

// Every per-axis array is x y z. Machine coordinates per axis: 0 at the home switch's edge, + along
// the machine's + axis (X and Y: the table's own displacement, Z: the head's), workspace [0, workspace_mm].
struct RigFacts {
  // ---- The mill (Sherline 3-axis) and its motion controller (CY545 on an MMC-4S board, RS-232; or LinuxCNC).
  // The facts marked (cy545) are the CY545's and its board's: a LinuxCNC mill leaves them at the
  // compiled-in values, which nothing on its path reads (LinuxCNC's own come from `linuxcnc`).
  MachineController controller;
  LinuxcncFacts linuxcnc;                   // (linuxcnc) the compiled-in rig has none: "127.0.0.1", 5007, no passwords
  std::array<double, 3> workspace_mm;       // machine workspace: the box [0,X]x[0,Y]x[0,Z]
  // World to machine, per axis: +1 counts along the world axis, -1 against it. X and Y move the table
  // (the work moves under the tool) and every axis counts into the workspace from its switch: all -1.
  std::array<int, 3> machine_sign;
  double steps_per_mm;                      // motor resolution, every axis (16000 steps/inch)
  double max_speed_mm_per_s;                // per axis (cy545)
  double step_rate_steps_per_s;             // the CY545's R and F: all axes together, one at a time (cy545)
  std::array<double, 3> backlash_mm;        // (cy545; LinuxCNC compensates its own)
  double machine_update_hz;                 // the machine link's updates (at most 9 with LinuxCNC)
  std::uint32_t serial_baud;                // the CY545's RS-232 line, 8N1 (cy545)
  // How far each axis can travel past the workspace: below 0 is the home switch's closed zone down to
  // the low hard stop, above the workspace a margin up to the high hard stop. From here to
  // watchdog_relay_timeout_ns: (cy545), the switches, the MMC-4S and the CY545 driver's homing.
  double home_overtravel_mm;
  double far_overtravel_mm;
  double home_switch_edge_mm;               // the switch is closed below this machine coordinate, open at and above
  hal::cy545::Mmc4sWiring mmc4s;            // output-mux, input-mux and relay wiring, switch levels, latching
  // Homing (the CY545 driver's legs, hal/cy545): its rates, how far a leg may run into the switch, the
  // slack the departure may turn before the axis moves, the longest approach, the switch's closed zone.
  double homing_speed_mm_per_s;             // under max_speed_mm_per_s
  double homing_slow_speed_mm_per_s;        // the last, edge-finding steps
  double homing_chunk_mm;
  double homing_slack_mm;                   // above the largest backlash
  double homing_travel_mm;                  // more than the whole travel
  double home_switch_zone_mm;               // more than home_overtravel_mm: a switch closed this far out is miswired
  std::array<std::uint8_t, 3> homing_order; // the axes in the order they home (0 x, 1 y, 2 z): Z first
  // The hardware watchdog relay in the spindle's and drivers' power: it opens when the heartbeat output
  // has not changed for this long (the driver toggles it every heartbeat period / 2).
  hal::MonotonicNs watchdog_relay_timeout_ns;

  // ---- The haptic device (Suzuki 5-DOF) and the cycle.
  std::array<double, 3> haptic_workspace_mm;  // the device's reach; its origin at a corner in the programs' frame
  double device_reach_margin_mm;            // a sample this far outside the reach is still a sample
  double haptic_to_machine_scale;           // device millimetres per machine (world) millimetre
  double force_limit_n;                     // the operator can always overpower this
  double torque_limit_nmm;                  // the two displayed torques, in magnitude
  double angle_limit_rad;                   // the two sensed angles, in magnitude
  double haptic_rate_hz;                    // the cycle

  // ---- The controller on this rig.
  // The virtual tool is held to what the mill follows over the serial line: 1.4 mm/s per axis and
  // 1000 steps/s are its stepping, but each update also spends about 15 ms of its 33 on the serial
  // line, so 1 mm/s per axis and in |dx| + |dy| + |dz|.
  double virtual_tool_speed_mm_per_s;
  // The virtual tool keeps this far clear of the part, so the mill always has a legal staircase along
  // its path (motion::follow_standoff_needed_mm says how much that takes; asserted below). The
  // operator feels the wall this far out, and this much stock is left on the part.
  double machine_standoff_mm;
  double stock_model_cell_mm;               // the controller's model of the machined stock
  int overrun_limit;                        // more overruns in a row than this: a safe state
  int stale_periods;                        // more periods than this without a fresh sample: a safe state
  bool start_held;                          // the cycle starts held until the hand is held still near the tool

  bool operator==(const RigFacts&) const = default;  // a configuration against the compiled-in defaults
};

inline constexpr RigFacts kRig{
    .controller = MachineController::Cy545,
    .linuxcnc = {.address = fixed_text<16>("127.0.0.1"),
                 .port = 5007,
                 .connect_password = {},
                 .enable_password = {},
                 .max_velocity_mm_per_s = {},
                 .max_acceleration_mm_per_s2 = {},
                 .max_linear_velocity_mm_per_s = 0.0},
    .workspace_mm = {50.0, 25.0, 25.0},
    .machine_sign = {-1, -1, -1},
    .steps_per_mm = 640.0,
    .max_speed_mm_per_s = 1.4,
    .step_rate_steps_per_s = 1000.0,
    .backlash_mm = {0.125, 0.05, 0.125},
    .machine_update_hz = 30.0,
    .serial_baud = 57600,
    .home_overtravel_mm = 3.0,
    .far_overtravel_mm = 5.0,
    .home_switch_edge_mm = 0.0,
    .mmc4s = {.motor_channel = {0, 1, 2},
              .home_input = {0, 1, 2},
              .spindle_output = 4,
              .heartbeat_output = 5,
              .heartbeat_period_ns = 400'000'000,  // the relay drops after about 1 s without a change
              .home_switch_closed_level = {true, true, true},
              .channel_lines_latch_data = true,
              .step_direction = {1, 1, 1}},
    .homing_speed_mm_per_s = 1.25,
    .homing_slow_speed_mm_per_s = 0.3125,
    .homing_chunk_mm = 0.1,
    .homing_slack_mm = 0.4,
    .homing_travel_mm = 64.0,
    .home_switch_zone_mm = 4.0,
    .homing_order = {2, 0, 1},
    .watchdog_relay_timeout_ns = 1'000'000'000,
    .haptic_workspace_mm = {500.0, 250.0, 250.0},
    .device_reach_margin_mm = 25.0,
    .haptic_to_machine_scale = 10.0,
    .force_limit_n = 5.0,
    .torque_limit_nmm = 200.0,
    .angle_limit_rad = 3.2,
    .haptic_rate_hz = 1000.0,
    .virtual_tool_speed_mm_per_s = 1.0,
    .machine_standoff_mm = 0.015,
    .stock_model_cell_mm = 0.05,
    .overrun_limit = 3,
    .stale_periods = 5,
    .start_held = true,
};

// ---- What follows from the facts (of any rig the configuration describes: rig_config.hpp; the
// constants below are this rig's, the compiled-in defaults).

inline constexpr int kAxisCount = 3;

// The cycle's period and the machine's update, in nanoseconds (1 ms; 33.3 ms, truncated).
inline constexpr hal::MonotonicNs period_ns(const RigFacts& facts) {
  return static_cast<hal::MonotonicNs>(1e9 / facts.haptic_rate_hz);
}
inline constexpr hal::MonotonicNs update_ns(const RigFacts& facts) {
  return static_cast<hal::MonotonicNs>(1e9 / facts.machine_update_hz);
}
inline constexpr hal::MonotonicNs kPeriodNs = period_ns(kRig);
inline constexpr hal::MonotonicNs kUpdateNs = update_ns(kRig);
static_assert(kPeriodNs == 1'000'000 && kUpdateNs == 1'000'000'000 / 30);

// Where the tool tip is in the world with the machine at home, before any touch-off: the workspace's
// far top corner (X and Y's switches at the table's travel end, Z's at the top), so that every axis
// counts from there into the workspace (machine_sign).
inline constexpr std::array<double, 3> home_world_mm(const RigFacts& facts) { return facts.workspace_mm; }
inline constexpr std::array<double, 3> kHomeWorldMm = home_world_mm(kRig);

inline constexpr double largest_backlash_mm(const RigFacts& facts = kRig) {
  double largest = 0.0;
  for (const double backlash : facts.backlash_mm) {
    largest = backlash > largest ? backlash : largest;
  }
  return largest;
}

inline constexpr double travel_min_mm(int axis, const RigFacts& facts = kRig) {
  static_cast<void>(axis);
  return facts.home_switch_edge_mm - facts.home_overtravel_mm;
}
inline constexpr double travel_max_mm(int axis, const RigFacts& facts = kRig) {
  return facts.workspace_mm[static_cast<std::size_t>(axis)] + facts.far_overtravel_mm;
}

// Millimetres to whole motor steps, rounded to nearest (every value used here is a whole number).
inline constexpr long long mm_to_steps(double mm, const RigFacts& facts = kRig) {
  const double steps = mm * facts.steps_per_mm;
  return static_cast<long long>(steps < 0.0 ? steps - 0.5 : steps + 0.5);
}

// Backlash per axis in motor steps: 80, 32, 80.
inline constexpr long long backlash_steps(int axis, const RigFacts& facts = kRig) {
  return mm_to_steps(facts.backlash_mm[static_cast<std::size_t>(axis)], facts);
}
static_assert(backlash_steps(0) == 80 && backlash_steps(1) == 32 && backlash_steps(2) == 80,
              "backlash must be a whole number of steps");

// ---- A LinuxCNC mill's budget. Each update is one G1 in exact-path mode (G61): LinuxCNC starts it
// from rest and brings the axes to rest at its end, so an axis with top speed v (mm/s) and
// acceleration a (mm/s^2) covers at most, in one update of T seconds,
//   d(T) = a T^2 / 4        when T <= 2 v / a (it never reaches v: accelerate half the time, brake half),
//   d(T) = v (T - v / a)    otherwise (accelerate for v / a, cruise, brake for v / a).
// Both give v^2 / a at T = 2 v / a. v is the axis's MAX_VELOCITY, under [TRAJ] MAX_LINEAR_VELOCITY
// when the INI gives one (no axis moves faster than the path); a is its MAX_ACCELERATION.
inline constexpr double rest_to_rest_mm(double period_s, double max_velocity_mm_per_s, double max_acceleration_mm_per_s2) {
  const double v = max_velocity_mm_per_s;
  const double a = max_acceleration_mm_per_s2;
  return period_s <= 2.0 * v / a ? a * period_s * period_s / 4.0 : v * (period_s - v / a);
}
inline constexpr double linuxcnc_axis_velocity_mm_per_s(int axis, const RigFacts& facts) {
  const double v = facts.linuxcnc.max_velocity_mm_per_s[static_cast<std::size_t>(axis)];
  const double path = facts.linuxcnc.max_linear_velocity_mm_per_s;
  return path > 0.0 && path < v ? path : v;
}
// How far `axis` can go in one machine update, from rest to rest (mm).
inline constexpr double linuxcnc_update_move_mm(int axis, const RigFacts& facts) {
  return rest_to_rest_mm(1.0 / facts.machine_update_hz, linuxcnc_axis_velocity_mm_per_s(axis, facts),
                         facts.linuxcnc.max_acceleration_mm_per_s2[static_cast<std::size_t>(axis)]);
}
inline constexpr double linuxcnc_shortest_update_move_mm(const RigFacts& facts) {
  double shortest = linuxcnc_update_move_mm(0, facts);
  for (int axis = 1; axis < 3; ++axis) {
    shortest = linuxcnc_update_move_mm(axis, facts) < shortest ? linuxcnc_update_move_mm(axis, facts) : shortest;
  }
  return shortest;
}
inline constexpr double linuxcnc_longest_update_move_mm(const RigFacts& facts) {
  double longest = linuxcnc_update_move_mm(0, facts);
  for (int axis = 1; axis < 3; ++axis) {
    longest = linuxcnc_update_move_mm(axis, facts) > longest ? linuxcnc_update_move_mm(axis, facts) : longest;
  }
  return longest;
}

// What the machine side's planner may spend: the mill's speed, one update, the backlash to take up.
// The CY545 steps one axis at a time: its speed per axis, its step rate for all of them, its backlash.
// LinuxCNC moves in one coordinated straight segment (MachinePath::Straight) and takes up its own
// backlash: every axis may move the shortest d(T) of the three in an update (as a speed, d(T) / T),
// and the axes' sum is not limited (three times that).
inline constexpr motion::PlannerLimits planner_limits(const RigFacts& facts) {
  const double update_s = 1.0 / facts.machine_update_hz;
  if (facts.controller == MachineController::Linuxcnc) {
    const double speed = linuxcnc_shortest_update_move_mm(facts) / update_s;
    return {{speed, 3.0 * speed * facts.steps_per_mm, facts.steps_per_mm}, update_s, {0, 0, 0}, motion::MachinePath::Straight};
  }
  return {{facts.max_speed_mm_per_s, facts.step_rate_steps_per_s, facts.steps_per_mm},
          update_s,
          {static_cast<std::int32_t>(backlash_steps(0, facts)), static_cast<std::int32_t>(backlash_steps(1, facts)),
           static_cast<std::int32_t>(backlash_steps(2, facts))},
          motion::MachinePath::Staircase};
}
inline constexpr motion::PlannerLimits kPlannerLimits = planner_limits(kRig);

// The standoff the planner's fallback staircase needs at this rig's steps and cycle (13.5 um on this
// rig: 5 steps per axis); the configured one must cover it.
inline constexpr double standoff_needed_mm(const RigFacts& facts) {
  return motion::follow_standoff_needed_mm(facts.steps_per_mm, facts.virtual_tool_speed_mm_per_s / facts.haptic_rate_hz);
}
static_assert(kRig.machine_standoff_mm >= standoff_needed_mm(kRig),
              "the standoff is under what the planner's fallback staircase needs");
static_assert(motion::follow_fallback_fits(kPlannerLimits), "one update's budget must cover the fallback staircase");

// The CY545 driver's configuration on a rig: its wiring, and its rates and homing in motor steps.
inline constexpr hal::cy545::Cy545Motion cy545_motion(const RigFacts& facts) {
  return {
      .step_rate = static_cast<std::uint32_t>(facts.step_rate_steps_per_s),
      .update_period_s = 1.0 / facts.machine_update_hz,
      .homing_rate = static_cast<std::uint32_t>(mm_to_steps(facts.homing_speed_mm_per_s, facts)),
      .homing_slow_rate = static_cast<std::uint32_t>(mm_to_steps(facts.homing_slow_speed_mm_per_s, facts)),
      .homing_chunk_steps = static_cast<std::int32_t>(mm_to_steps(facts.homing_chunk_mm, facts)),
      .homing_slack_steps = static_cast<std::int32_t>(mm_to_steps(facts.homing_slack_mm, facts)),
      .homing_travel_steps = static_cast<std::int32_t>(mm_to_steps(facts.homing_travel_mm, facts)),
      .home_switch_zone_steps = static_cast<std::int32_t>(mm_to_steps(facts.home_switch_zone_mm, facts)),
      .homing_order = facts.homing_order,
  };
}
inline constexpr hal::cy545::Cy545Config cy545_config(const RigFacts& facts) {
  return {facts.mmc4s, cy545_motion(facts)};
}
inline constexpr hal::cy545::Cy545Motion kCy545Motion = cy545_motion(kRig);
static_assert(kCy545Motion.homing_rate == 800 && kCy545Motion.homing_slow_rate == 200 &&
              kCy545Motion.homing_chunk_steps == 64 && kCy545Motion.homing_slack_steps == 256 &&
              kCy545Motion.homing_travel_steps == 40960 && kCy545Motion.home_switch_zone_steps == 2560);
static_assert(kRig.homing_speed_mm_per_s < kRig.max_speed_mm_per_s && kRig.homing_slack_mm > largest_backlash_mm() &&
              kRig.home_switch_zone_mm > kRig.home_overtravel_mm);
inline constexpr hal::cy545::Cy545Config kCy545 = cy545_config(kRig);

// The LinuxCNC link's configuration on a rig: where linuxcncrsh listens and its passwords, the
// planner's grid (machine.steps_per_mm: step n is LinuxCNC's machine n / steps_per_mm mm), the
// workspace as its travel, the longest move an update may hold (the fastest axis's d(T) plus the
// step of rounding the planner keeps room for) and the feed of every G1: a path speed, so sqrt(3)
// times the fastest axis's MAX_VELOCITY, that a diagonal move runs its axes as fast as a move along
// one (LinuxCNC holds each axis to its own limits under it; the budget assumed each axis's own).
inline constexpr hal::linuxcnc::LinuxcncConfig linuxcnc_config(const RigFacts& facts) {
  hal::linuxcnc::LinuxcncConfig config{};
  config.address = facts.linuxcnc.address;
  config.port = facts.linuxcnc.port;
  config.connect_password = facts.linuxcnc.connect_password;
  config.enable_password = facts.linuxcnc.enable_password;
  config.steps_per_mm = facts.steps_per_mm;
  config.travel_mm = facts.workspace_mm;
  config.max_move_mm = linuxcnc_longest_update_move_mm(facts) + 1.0 / facts.steps_per_mm;
  double fastest = 0.0;
  for (const double velocity : facts.linuxcnc.max_velocity_mm_per_s) {
    fastest = velocity > fastest ? velocity : fastest;
  }
  config.feed_mm_per_min = 60.0 * 1.7320508075688772 * fastest;
  return config;
}

// What the haptic backends accept from this device: its reach plus the margin per side around
// `centre_mm`, the two angles, the force and torque limits.
inline constexpr hal::HapticRange device_range(const RigFacts& facts, const std::array<double, 3>& centre_mm) {
  return {{facts.haptic_workspace_mm[0] / 2.0 + facts.device_reach_margin_mm,
           facts.haptic_workspace_mm[1] / 2.0 + facts.device_reach_margin_mm,
           facts.haptic_workspace_mm[2] / 2.0 + facts.device_reach_margin_mm},
          facts.angle_limit_rad,
          facts.force_limit_n,
          facts.torque_limit_nmm,
          {centre_mm[0], centre_mm[1], centre_mm[2]}};
}
inline constexpr hal::HapticRange device_range(const std::array<double, 3>& centre_mm) {
  return device_range(kRig, centre_mm);
}
// The programs' frame: the device's origin at a corner of its reach, device space [0, 500] x [0, 250]
// x [0, 250] (world = device / 10).
inline constexpr hal::HapticRange programs_device_range(const RigFacts& facts) {
  return device_range(facts, {facts.haptic_workspace_mm[0] / 2.0, facts.haptic_workspace_mm[1] / 2.0,
                              facts.haptic_workspace_mm[2] / 2.0});
}
inline constexpr hal::HapticRange kDeviceRange = programs_device_range(kRig);
// The same reach centred on the origin (the backends' own frame, as their tests use it).
inline constexpr hal::HapticRange kCentredDeviceRange = device_range({0.0, 0.0, 0.0});

}  // namespace stencil::board::sherline_suzuki
