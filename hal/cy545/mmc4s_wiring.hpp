// The MMC-4S multiplexer board's wiring on a rig: which ports select the motors, read the home
// switches, run the spindle and beat the watchdog relay. The CY545 driver is given it, and so is the
// simulated board (sim/cy545), both by the rig's board.
#pragma once

#include <array>
#include <cstdint>

#include "hal/clock.hpp"

namespace stencil::hal::cy545 {

// How the rig's MMC-4S board is wired to its mill, its switches and its watchdog relay, and how its
// latches and switches behave: facts of the rig, which its board passes in (the Sherline rig's:
// board/sherline_suzuki/rig_facts.hpp). No defaults here: a guess is a mill that runs away.
struct Mmc4sWiring {
  std::array<std::uint8_t, 3> motor_channel;  // output-mux port (= motor channel) of x y z
  std::array<std::uint8_t, 3> home_input;     // input-mux port of their home switches
  std::uint8_t spindle_output;                // general-purpose output that runs the spindle (1 = on)
  // The watchdog relay's heartbeat: a general-purpose output toggled every heartbeat_period_ns / 2
  // while the machine side runs (homing included); -1: none (a rig without the relay).
  int heartbeat_output;
  MonotonicNs heartbeat_period_ns;
  // The level user bit 1 reads, through the input mux, while an axis's home switch is CLOSED (normally
  // open switches pulled up read 0): wrong, the approach runs away.
  std::array<bool, 3> home_switch_closed_level;
  // How the MMC-4S latches a motor channel (its manual is not at hand): true, each line latches its
  // data bit, so the old channel's line is latched off before the new one's on (right under either
  // reading, at six commands a change of axis instead of three); false, the board latches the
  // address (the thesis's table 5-1: output ports 0-3 are "motor/driver addresses"), one select.
  // Measure it at commissioning: select X, then Y, step, and see whether X moves.
  bool channel_lines_latch_data;
  // Per axis x y z, the motor driver's direction line: +1, the chip's '+' steps move the axis away from
  // its home switch (into the workspace); -1, the line is wired the other way round, and the driver
  // sends '-' for those. Wrong, homing runs away from the switch and finds none.
  std::array<int, 3> step_direction;

  bool operator==(const Mmc4sWiring&) const = default;
};

}  // namespace stencil::hal::cy545
