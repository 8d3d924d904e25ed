// The simulated CY545: serial input with its 3-character buffer, command execution on a virtual clock.
#include "sim/cy545/cy545_chip.hpp"

#include <utility>

#include "sim/cy545/cy545_protocol.hpp"

namespace stencil::sim::cy545 {

namespace {

constexpr hal::MonotonicNs kNsPerMillisecond = 1'000'000;
constexpr std::uint32_t kRegisterModulus = kMax24Bit + 1;
constexpr std::uint8_t kBusyBit = static_cast<std::uint8_t>(1u << kBitBusyCts);

std::uint32_t wrap24(std::int64_t value) {
  const std::int64_t modulus = kRegisterModulus;
  return static_cast<std::uint32_t>(((value % modulus) + modulus) % modulus);
}

}  // namespace

Cy545Chip::Cy545Chip(Mmc4sBoard& board, hal::MonotonicNs start_ns) : board_(board), now_ns_(start_ns) {
  line_.reserve(static_cast<std::size_t>(kMaxLineCharacters) + 1);
  power_on_reset();
}

void Cy545Chip::power_on_reset() {
  activity_ = Activity::idle;
  baud_locked_ = false;
  buffered_ = 0;
  line_.clear();
  initialise_registers();
}

void Cy545Chip::initialise_registers() {
  position_ = 0;
  step_count_ = 0;
  direction_ = StepDirection::positive;
  rate_ = kDefaultRateStepsPerSecond;
  first_rate_ = kDefaultRateStepsPerSecond;
  slope_ = 0;
  mode_ = kDefaultMode;  // the manual's power-up value: ASCII commands, serial query output
  binary_ = Binary{};
  data_bus_ = 0;
  write_user_bits(0);
}

std::string Cy545Chip::take_output() { return std::exchange(output_, std::string{}); }

std::uint8_t Cy545Chip::pin_levels() const {
  std::uint8_t levels = static_cast<std::uint8_t>(latches_ & ~kBusyBit);
  if (!busy()) levels = static_cast<std::uint8_t>(levels | kBusyBit);
  if (((static_cast<unsigned>(latches_) >> kBitReadStrobe) & 1u) != 0) {
    const int address = (latches_ >> kBitAddressLow) & 0x7;
    const std::uint8_t data_bit = static_cast<std::uint8_t>(1u << kBitData);
    levels = static_cast<std::uint8_t>(board_.input_level(address) ? (levels | data_bit) : (levels & ~data_bit));
  }
  return levels;
}

bool Cy545Chip::bit_matches(std::uint32_t bit_argument) const {
  const int bit = static_cast<int>(bit_argument & 0x7);
  const bool want_high = bit_argument < 0x10;
  const bool high = ((static_cast<unsigned>(pin_levels()) >> bit) & 1u) != 0;
  return high == want_high;
}

void Cy545Chip::receive(std::uint8_t byte, hal::MonotonicNs now_ns) {
  advance_to(now_ns);
  ++counters_.bytes_received;
  if (!baud_locked_) {
    // Adaptive baud: the first CR sets the rate; anything before it is noise to the chip.
    if (byte == kCarriageReturn) {
      baud_locked_ = true;
    } else {
      ++counters_.bytes_before_baud_lock;
    }
    return;
  }
  if (busy()) {
    if (buffered_ < kReceiveBufferBytes) {
      buffer_[static_cast<std::size_t>(buffered_++)] = byte;
    } else {
      ++counters_.bytes_dropped_while_busy;
    }
    return;
  }
  parse_byte(byte, now_ns_);
}

void Cy545Chip::parse_byte(std::uint8_t byte, hal::MonotonicNs at_ns) {
  if ((mode_ & kModeAsciiBit) == 0) {
    parse_binary_byte(byte, at_ns);
    return;
  }
  if (byte == kCarriageReturn) {
    execute_line(at_ns);
    line_.clear();
    return;
  }
  // Past the longest legal line the rest is not kept: the line is refused as too long anyway.
  if (line_.size() <= static_cast<std::size_t>(kMaxLineCharacters)) line_.push_back(static_cast<char>(byte));
}

// Binary mode reads bytes as letter, count, data whatever they are: ASCII text sent now is taken
// apart this way, and a wrong count swallows the bytes after it (the manual: only a hardware reset
// reliably resynchronises).
void Cy545Chip::parse_binary_byte(std::uint8_t byte, hal::MonotonicNs at_ns) {
  switch (binary_.stage) {
    case Binary::Stage::letter:
      binary_.letter = static_cast<char>(byte);
      binary_.stage = Binary::Stage::count;
      return;
    case Binary::Stage::count:
      binary_.count = byte;
      binary_.received = 0;
      binary_.stage = Binary::Stage::data;
      break;
    case Binary::Stage::data:
      if (binary_.received < binary_.data.size()) binary_.data[binary_.received] = byte;
      ++binary_.received;
      break;
  }
  if (binary_.received < binary_.count) return;
  binary_.stage = Binary::Stage::letter;
  const ParseResult result = parse_binary_command(binary_.letter, binary_.data.data(), binary_.count);
  if (result.status != ParseStatus::command) {
    ++(result.status == ParseStatus::malformed ? counters_.malformed_lines : counters_.unsupported_commands);
    last_error_ = Cy545LineError{std::string(1, binary_.letter), result.reason, result.column, result.status};
    return;
  }
  ++counters_.commands_executed;
  execute(result.command, at_ns);
}

void Cy545Chip::execute_line(hal::MonotonicNs at_ns) {
  const ParseResult result = parse_command_line(line_);
  switch (result.status) {
    case ParseStatus::empty:
      return;
    case ParseStatus::malformed:
    case ParseStatus::unsupported:
      if (result.status == ParseStatus::malformed) {
        ++counters_.malformed_lines;
      } else {
        ++counters_.unsupported_commands;
      }
      last_error_ = Cy545LineError{line_, result.reason, result.column, result.status};
      return;
    case ParseStatus::command:
      ++counters_.commands_executed;
      execute(result.command, at_ns);
      return;
  }
}

void Cy545Chip::execute(const Cy545Command& command, hal::MonotonicNs at_ns) {
  execute_command(command, at_ns);
  // Every command takes the chip some time even when it moves nothing (set_command_time_ns); the
  // bytes that arrive meanwhile wait in the three-character buffer, and the rest are lost.
  if (command_time_ns_ > 0 && activity_ == Activity::idle) {
    delay_end_ns_ = at_ns + command_time_ns_;
    activity_ = Activity::delaying;
  }
}

void Cy545Chip::execute_command(const Cy545Command& command, hal::MonotonicNs at_ns) {
  const std::uint32_t argument = command.argument;
  switch (command.letter) {
    case 'A': position_ = argument; break;
    case 'N': step_count_ = argument; break;
    case '+': direction_ = StepDirection::positive; break;
    case '-': direction_ = StepDirection::negative; break;
    case 'G': start_move(step_count_, direction_, at_ns); break;
    case 'P':
      if (argument > position_) {
        start_move(argument - position_, StepDirection::positive, at_ns);
      } else if (argument < position_) {
        start_move(position_ - argument, StepDirection::negative, at_ns);
      }
      break;
    case 'R': rate_ = argument; break;
    case 'F': first_rate_ = argument; break;
    case 'S': slope_ = argument; break;
    case 'O': mode_ = argument; break;
    case 'B': apply_bit_command(argument); break;
    case 'H': start_home(argument, at_ns); break;
    case 'W':
      if (!bit_matches(argument)) {
        wait_bit_argument_ = argument;
        activity_ = Activity::waiting_for_bit;
      }
      break;
    case 'I': initialise_registers(); break;
    case 'D':
      if (argument > 0) {
        delay_end_ns_ = at_ns + static_cast<hal::MonotonicNs>(argument) * kNsPerMillisecond;
        activity_ = Activity::delaying;
      }
      break;
    case '?':
      switch (command.query_letter) {
        case 'A':
        case 'P':
          reply(command.query_letter, wrap24(static_cast<std::int64_t>(position_) + query_position_offset_));
          break;
        case 'N': reply('N', step_count_); break;
        case 'R': reply('R', rate_); break;
        case 'F': reply('F', first_rate_); break;
        case 'S': reply('S', slope_); break;
        case 'O': reply('O', mode_); break;
        case 'B': reply('B', pin_levels()); break;
        default: break;  // the parser admits only the letters above
      }
      break;
    default: break;  // the parser admits only the letters above
  }
}

void Cy545Chip::apply_bit_command(std::uint32_t argument) {
  std::uint32_t code = argument;
  if (code >= 0x20 && code < 0x40) code -= 0x20;  // 20H-3FH: the same as 00H-1FH
  std::uint8_t latches = latches_;
  const std::uint8_t low_six = static_cast<std::uint8_t>(code & 0x3F);
  if (code < 0x08) {
    latches = static_cast<std::uint8_t>(latches | (1u << code));
  } else if (code < 0x10) {
    data_bus_ = static_cast<std::uint8_t>(data_bus_ | (1u << (code - 0x08)));
  } else if (code < 0x18) {
    latches = static_cast<std::uint8_t>(latches & ~(1u << (code - 0x10)));
  } else if (code < 0x20) {
    data_bus_ = static_cast<std::uint8_t>(data_bus_ & ~(1u << (code - 0x18)));
  } else if (code < 0x80) {
    latches = static_cast<std::uint8_t>((latches & 0xC0) | low_six);
  } else if (code < 0xC0) {
    latches = static_cast<std::uint8_t>(latches & (0xC0 | low_six));
  } else {
    latches = static_cast<std::uint8_t>(latches | low_six);
  }
  write_user_bits(latches);
}

void Cy545Chip::write_user_bits(std::uint8_t latches) {
  const std::uint8_t before = latches_;
  latches_ = static_cast<std::uint8_t>(latches & ~kBusyBit);  // bit 6 belongs to the chip's CTS
  board_.on_user_bits_written(before, latches_, now_ns_);
}

void Cy545Chip::start_move(std::uint32_t steps, StepDirection direction, hal::MonotonicNs at_ns) {
  if (steps == 0) return;
  move_.start_ns = at_ns;
  move_.profile = MoveProfile(steps, rate_, first_rate_, slope_);
  move_.steps_done = 0;
  move_.direction = direction;
  activity_ = Activity::moving;
}

void Cy545Chip::start_home(std::uint32_t bit_argument, hal::MonotonicNs at_ns) {
  home_.bit_argument = bit_argument;
  home_.stepping_away = bit_matches(bit_argument);
  home_.phase_start_ns = at_ns;
  home_.step_interval_ns = hal::kNsPerSecond / static_cast<hal::MonotonicNs>(first_rate_);
  home_.steps_in_phase = 0;
  activity_ = Activity::homing;
}

void Cy545Chip::issue_step(StepDirection direction) {
  position_ = wrap24(static_cast<std::int64_t>(position_) + static_cast<std::int64_t>(direction));
  ++counters_.steps_issued;
  board_.step_pulse(direction);
}

void Cy545Chip::finish(hal::MonotonicNs at_ns) {
  activity_ = Activity::idle;
  now_ns_ = at_ns;
  // The buffered characters are read now, as if they had just arrived; one of them may start a new
  // command, and the rest then wait in the buffer again.
  while (buffered_ > 0 && !busy()) {
    const std::uint8_t byte = buffer_[0];
    for (int i = 1; i < buffered_; ++i) buffer_[static_cast<std::size_t>(i - 1)] = buffer_[static_cast<std::size_t>(i)];
    --buffered_;
    parse_byte(byte, at_ns);
  }
}

bool Cy545Chip::run_move(hal::MonotonicNs now_ns) {
  while (move_.steps_done < move_.profile.steps()) {
    const hal::MonotonicNs step_ns = move_.start_ns + move_.profile.step_offset_ns(move_.steps_done + 1);
    if (step_ns > now_ns) return true;
    issue_step(move_.direction);
    ++move_.steps_done;
  }
  finish(move_.start_ns + move_.profile.duration_ns());
  return false;
}

bool Cy545Chip::run_home(hal::MonotonicNs now_ns) {
  for (;;) {
    const hal::MonotonicNs step_ns =
        home_.phase_start_ns + static_cast<hal::MonotonicNs>(home_.steps_in_phase + 1) * home_.step_interval_ns;
    if (!home_.stepping_away && bit_matches(home_.bit_argument)) {
      // Already on the edge (no step needed), or the last step reached it.
      position_ = 0;
      finish(home_.steps_in_phase == 0 ? home_.phase_start_ns
                                       : home_.phase_start_ns + static_cast<hal::MonotonicNs>(home_.steps_in_phase) *
                                                                    home_.step_interval_ns);
      return false;
    }
    if (home_.steps_in_phase >= kMax24Bit) {
      ++counters_.home_aborts;
      finish(home_.phase_start_ns + static_cast<hal::MonotonicNs>(home_.steps_in_phase) * home_.step_interval_ns);
      return false;
    }
    if (step_ns > now_ns) return true;
    issue_step(home_.stepping_away ? StepDirection::negative : StepDirection::positive);
    ++home_.steps_in_phase;
    if (home_.stepping_away && !bit_matches(home_.bit_argument)) {
      // Off the signal: turn round and seek the edge in the + direction.
      home_.stepping_away = false;
      home_.phase_start_ns = step_ns;
      home_.steps_in_phase = 0;
    }
  }
}

void Cy545Chip::advance_to(hal::MonotonicNs now_ns) {
  if (now_ns < now_ns_) return;
  for (;;) {
    bool waiting = false;
    switch (activity_) {
      case Activity::idle:
        now_ns_ = now_ns;
        return;
      case Activity::moving:
        waiting = run_move(now_ns);
        break;
      case Activity::homing:
        waiting = run_home(now_ns);
        break;
      case Activity::delaying:
        waiting = delay_end_ns_ > now_ns;
        if (!waiting) finish(delay_end_ns_);
        break;
      case Activity::waiting_for_bit:
        // Inputs change only between services, so the match is seen at this service's time.
        waiting = !bit_matches(wait_bit_argument_);
        if (!waiting) finish(now_ns);
        break;
    }
    if (waiting) {
      now_ns_ = now_ns;
      return;
    }
  }
}

void Cy545Chip::reply(char letter, std::uint32_t value) {
  ++counters_.replies;
  output_.push_back(letter);
  output_.push_back('=');
  output_ += std::to_string(value);
  output_.push_back(static_cast<char>(kCarriageReturn));
}

}  // namespace stencil::sim::cy545
