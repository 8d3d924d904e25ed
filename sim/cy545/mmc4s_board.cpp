// The MMC-4S multiplexer board: decodes the CY545's user bits into channel selection, outputs and inputs.
#include "sim/cy545/mmc4s_board.hpp"

#include <cstddef>

#include "sim/cy545/cy545_protocol.hpp"

namespace stencil::sim::cy545 {

namespace {

bool bit_of(std::uint8_t bits, int bit) { return ((static_cast<unsigned>(bits) >> bit) & 1u) != 0; }
int address_of(std::uint8_t bits) { return (bits >> kBitAddressLow) & 0x7; }

}  // namespace

Mmc4sBoard::Mmc4sBoard(SimulatedMill& mill, const hal::cy545::Mmc4sWiring& wiring) : mill_(mill), wiring_(wiring) {
  mill_.set_drivers_enabled(false);
  mill_.set_spindle_on(false);
}

void Mmc4sBoard::apply_power() {
  mill_.set_drivers_enabled(drivers_latched_ && relay_closed_);
  mill_.set_spindle_on(outputs_[wiring_.spindle_output] && relay_closed_);
}

void Mmc4sBoard::arm_watchdog_relay(int port, hal::MonotonicNs timeout_ns, hal::MonotonicNs now_ns) {
  relay_port_ = port;
  relay_timeout_ns_ = timeout_ns;
  last_heartbeat_ns_ = now_ns;
}

void Mmc4sBoard::advance_to(hal::MonotonicNs now_ns) {
  if (relay_port_ >= 0 && relay_closed_ && now_ns - last_heartbeat_ns_ > relay_timeout_ns_) {
    relay_closed_ = false;
    apply_power();
  }
}

void Mmc4sBoard::on_user_bits_written(std::uint8_t before, std::uint8_t after, hal::MonotonicNs at_ns) {
  advance_to(at_ns);
  drivers_latched_ = bit_of(after, kBitDriverEnable);
  apply_power();
  const bool strobe_rising = !bit_of(before, kBitWriteStrobe) && bit_of(after, kBitWriteStrobe);
  if (!strobe_rising) return;
  const int port = address_of(after);
  if (port < kMotorChannels) {
    if (latching_ == ChannelLatching::Address) {
      channel_on_ = {};
      channel_on_[static_cast<std::size_t>(port)] = true;
    } else {
      channel_on_[static_cast<std::size_t>(port)] = bit_of(after, kBitData);
    }
    ++channel_selections_;
    return;
  }
  const bool level = bit_of(after, kBitData);
  if (port == relay_port_ && level != outputs_[static_cast<std::size_t>(port)]) {
    last_heartbeat_ns_ = at_ns;
    relay_closed_ = true;
  }
  outputs_[static_cast<std::size_t>(port)] = level;
  apply_power();
}

std::optional<Axis> Mmc4sBoard::axis_of_channel(int channel) const {
  for (int axis = 0; axis < kMillAxisCount; ++axis) {
    if (wiring_.motor_channel[static_cast<std::size_t>(axis)] == channel) return static_cast<Axis>(axis);
  }
  return std::nullopt;
}

bool Mmc4sBoard::input_level(int port) const {
  for (int axis = 0; axis < kMillAxisCount; ++axis) {
    if (wiring_.home_input[static_cast<std::size_t>(axis)] != port) continue;
    const auto a = static_cast<Axis>(axis);
    bool closed = mill_.home_switch_closed(a);
    const std::int64_t from_edge =
        mill_.axis_position_steps(a) - mill_.config().axes[static_cast<std::size_t>(axis)].home_switch_edge_steps;
    if (bounce_band_steps_ > 0 && from_edge >= -bounce_band_steps_ && from_edge < bounce_band_steps_) {
      bounce_state_ ^= bounce_state_ << 13U;
      bounce_state_ ^= bounce_state_ >> 17U;
      bounce_state_ ^= bounce_state_ << 5U;
      closed = (bounce_state_ & 1U) != 0;
    }
    return closed != home_inverted_;
  }
  if (port >= kMotorChannels && port < kMuxPorts) return general_inputs_[static_cast<std::size_t>(port)];
  return false;
}

std::optional<int> Mmc4sBoard::selected_channel() const {
  if (selected_channel_count() != 1) return std::nullopt;
  for (int channel = 0; channel < kMotorChannels; ++channel) {
    if (channel_on_[static_cast<std::size_t>(channel)]) return channel;
  }
  return std::nullopt;
}

int Mmc4sBoard::selected_channel_count() const {
  int count = 0;
  for (const bool on : channel_on_) count += on ? 1 : 0;
  return count;
}

void Mmc4sBoard::step_pulse(StepDirection direction) {
  bool stepped = false;
  for (int channel = 0; channel < kMotorChannels; ++channel) {
    if (!channel_on_[static_cast<std::size_t>(channel)]) continue;
    if (const std::optional<Axis> axis = axis_of_channel(channel)) {
      static_cast<void>(mill_.step_motor(*axis, direction));
      stepped = true;
    }
  }
  if (!stepped) ++steps_to_no_channel_;
}

bool Mmc4sBoard::general_output(int port) const {
  return port >= kMotorChannels && port < kMuxPorts && outputs_[static_cast<std::size_t>(port)];
}

void Mmc4sBoard::set_general_input(int port, bool level) {
  if (port >= kMotorChannels && port < kMuxPorts) general_inputs_[static_cast<std::size_t>(port)] = level;
}

}  // namespace stencil::sim::cy545
