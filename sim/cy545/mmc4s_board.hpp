// The MMC-4S multiplexer board between the CY545's user bits and the mill: channel latch, general-purpose
// outputs (spindle), input mux (home sensors), driver enable. Wiring and rules: cy545_protocol.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "hal/clock.hpp"
#include "hal/cy545/mmc4s_wiring.hpp"
#include "sim/mill/simulated_mill.hpp"

namespace stencil::sim::cy545 {

// How a write strobe at a motor channel's address (0-3) acts. The MMC-4S's own manual is not at
// hand and the thesis says only that "normally one channel is selected at a time", so the fake has
// both readings and defaults to the unkinder: a driver must be right under either.
enum class ChannelLatching : std::uint8_t {
  PerLine,  // each channel's line latches the data bit: 1 selects it, 0 deselects it; several can be
            // selected at once, and then every step pulse steps all of them
  Address,  // the board latches the address: that channel alone is selected, the data bit ignored
};

class Mmc4sBoard {
 public:
  // `wiring`: which output-mux port selects each axis's motor, which input-mux port reads its home
  // switch, which general-purpose output runs the spindle (the rig's board gives it).
  Mmc4sBoard(SimulatedMill& mill, const hal::cy545::Mmc4sWiring& wiring);

  void set_channel_latching(ChannelLatching latching) { latching_ = latching; }

  // The chip's user-bit output latches changed from `before` to `after` (bit 6 excluded), at `at_ns`.
  void on_user_bits_written(std::uint8_t before, std::uint8_t after, hal::MonotonicNs at_ns = 0);

  // The rig's hardware watchdog (README): a relay in the spindle's and the drivers' power that opens
  // when general-purpose output `port` has not changed for `timeout_ns`, and closes again at its next
  // change. Not armed by default: it is wiring beside the board, not the board.
  void arm_watchdog_relay(int port, hal::MonotonicNs timeout_ns, hal::MonotonicNs now_ns);
  // Opens the relay once the heartbeat is overdue (the fake calls it as its clock moves).
  void advance_to(hal::MonotonicNs now_ns);
  [[nodiscard]] bool watchdog_relay_closed() const { return relay_closed_; }

  // The level of input-mux port `port` (0..7).
  [[nodiscard]] bool input_level(int port) const;

  // A step pulse with the chip's direction line: goes to the selected channel's motor, if any.
  void step_pulse(StepDirection direction);

  // The one selected channel; none when no channel or (PerLine) more than one is selected.
  [[nodiscard]] std::optional<int> selected_channel() const;
  [[nodiscard]] int selected_channel_count() const;
  [[nodiscard]] bool general_output(int port) const;
  void set_general_input(int port, bool level);

  // The home switches as a real rig wires them. Inverted: the inputs read 0 while a switch is closed
  // (normally-closed contacts, or a pull-down), so a driver assuming the opposite seeks the wrong way.
  // Bounce: within `band_steps` of a switch's edge its contacts chatter, and each read is a coin
  // toss (a fixed sequence: deterministic runs); 0 is a perfect switch.
  void set_home_switches_inverted(bool inverted) { home_inverted_ = inverted; }
  void set_home_switch_bounce(std::int64_t band_steps) { bounce_band_steps_ = band_steps; }

  [[nodiscard]] std::int64_t steps_to_no_channel() const { return steps_to_no_channel_; }
  [[nodiscard]] std::int64_t channel_selections() const { return channel_selections_; }

  [[nodiscard]] SimulatedMill& mill() { return mill_; }
  [[nodiscard]] const SimulatedMill& mill() const { return mill_; }

 private:
  [[nodiscard]] std::optional<Axis> axis_of_channel(int channel) const;

  SimulatedMill& mill_;
  hal::cy545::Mmc4sWiring wiring_;
  ChannelLatching latching_ = ChannelLatching::PerLine;
  std::array<bool, 4> channel_on_{};  // motor channels 0..3 (Address: at most one)
  std::array<bool, 8> outputs_{};         // general-purpose outputs 4..7 (0..3 unused)
  std::array<bool, 8> general_inputs_{};  // general-purpose inputs 4..7
  void apply_power();  // the mill's spindle and drivers: the latches, through the relay

  int relay_port_ = -1;
  hal::MonotonicNs relay_timeout_ns_ = 0;
  hal::MonotonicNs last_heartbeat_ns_ = 0;
  bool relay_closed_ = true;
  bool drivers_latched_ = false;
  bool home_inverted_ = false;
  std::int64_t bounce_band_steps_ = 0;
  mutable std::uint32_t bounce_state_ = 0x9E3779B9U;  // xorshift32: reads near an edge advance it
  std::int64_t steps_to_no_channel_ = 0;
  std::int64_t channel_selections_ = 0;
};

}  // namespace stencil::sim::cy545
