// The CY545 driver: machine updates into channel-select, step-count, direction and go commands.
#include "hal/cy545/cy545_link.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace stencil::hal::cy545 {
namespace {

constexpr MonotonicNs kSecond = 1'000'000'000;

MonotonicNs steps_time_ns(std::int64_t steps, std::uint32_t rate) {
  return rate == 0 ? kSecond * 1000 : steps * kSecond / static_cast<MonotonicNs>(rate);
}

bool is_permutation(const std::array<std::uint8_t, 3>& order) {
  return order[0] < 3 && order[1] < 3 && order[2] < 3 && order[0] != order[1] && order[1] != order[2] &&
         order[0] != order[2];
}

}  // namespace

Cy545Link::Cy545Link(SerialPort& port, Clock& clock, const Cy545Config& config)
    : port_(port), clock_(clock), config_(config) {
  state_ = port_.is_open() ? MachineState::Open : MachineState::Closed;
}

void Cy545Link::latch_fault(MachineFault fault) {
  if (fault_ == MachineFault::None) {
    fault_ = fault;
  }
  state_ = MachineState::Fault;
  homed_ = false;
}

MachineResult Cy545Link::fail(MachineFault fault) {
  latch_fault(fault);
  return {false, MachineRefusal::None, fault};
}

MachineResult Cy545Link::refuse(MachineRefusal refusal) const { return {false, refusal, MachineFault::None}; }

void Cy545Link::started_running(MonotonicNs shortest_ns, MonotonicNs longest_ns) {
  const MonotonicNs now = clock_.now_ns();
  busy_until_ns_ = now + shortest_ns;
  busy_bound_ns_ = now + longest_ns;
  running_ = true;
}

// The chip reads nothing while it steps, and only three characters wait in its buffer. Once the
// move's computed time has passed, the driver asks "? P" and sends carriage returns until the
// answer comes: the three characters fit the buffer even if the chip is still busy, surplus
// carriage returns are dropped (buffer full) or are empty lines (no effect), and the answer, which
// can only come once the chip is free, also says whether it made every step. So no command ever
// meets a busy chip, however late the chip (or, on a pseudo-terminal, the process playing it) runs.
bool Cy545Link::wait_free(MonotonicNs deadline_ns) {
  if (!running_) {
    return true;
  }
  if (busy_until_ns_ > deadline_ns) {
    clock_.sleep_until_ns(deadline_ns);
    return false;
  }
  clock_.sleep_until_ns(busy_until_ns_);
  running_ = false;  // the probe below must not wait for itself
  port_.discard_input();
  CommandBytes probe{};
  static_cast<void>(query_command('P', probe));
  if (!write_bytes(std::string_view(probe.view().data(), probe.size - 1), deadline_ns)) {  // "? P", no CR yet
    return false;
  }
  const MonotonicNs give_up = std::min(deadline_ns, busy_bound_ns_ + config_.reply_timeout_ns);
  char reply[32];
  std::size_t size = 0;
  std::size_t kept = 0;
  while (true) {
    if (!write_bytes("\r", deadline_ns)) {
      return false;
    }
    const MonotonicNs now = clock_.now_ns();
    if (now >= give_up) {
      if (give_up == deadline_ns && deadline_ns < busy_bound_ns_ + config_.reply_timeout_ns) {
        running_ = true;  // the caller's bound ran out first: still unconfirmed, no fault
        return false;
      }
      std::snprintf(last_error_, sizeof last_error_,
                    "the controller did not report back within %lld ms of a move's end",
                    static_cast<long long>(config_.reply_timeout_ns / 1'000'000));
      latch_fault(MachineFault::Timeout);
      return false;
    }
    // A long seek is asked about less often than a short move.
    const MonotonicNs interval = std::max(config_.probe_interval_ns, (busy_bound_ns_ - busy_until_ns_) / 50);
    const PortIo io = port_.read_line(reply + kept, sizeof reply - kept, size, std::min(give_up, now + interval), clock_);
    bytes_received_ += size;
    kept += size;
    if (io == PortIo::Closed) {
      latch_fault(MachineFault::PortClosed);
      return false;
    }
    if (io == PortIo::TimedOut) {
      continue;
    }
    const ReplyParse parsed = parse_reply({reply, kept}, 'P');
    if (io != PortIo::Ok || parsed.status != ReplyStatus::Complete) {
      const unsigned byte = parsed.at < kept ? static_cast<unsigned char>(reply[parsed.at]) : 0U;
      std::snprintf(last_error_, sizeof last_error_, "reply to \"? P\": byte %zu is 0x%02X where %s was expected",
                    parsed.at, byte, parsed.status == ReplyStatus::Garbled ? parsed.expected : "a reply");
      latch_fault(MachineFault::GarbledReply);
      return false;
    }
    if (parsed.value != position_register_) {
      std::snprintf(last_error_, sizeof last_error_, "the controller reports position %u, %u was commanded",
                    parsed.value, position_register_);
      latch_fault(MachineFault::PositionMismatch);
      return false;
    }
    return true;
  }
}

bool Cy545Link::read_user_bits_when_free(std::uint8_t& levels, MonotonicNs deadline_ns) {
  port_.discard_input();
  // "? B" without its carriage return fits the chip's three-character buffer even while it steps;
  // the carriage returns after it complete the line once the chip is free (see wait_free).
  if (port_.write_all("? B", deadline_ns, clock_) != PortIo::Ok) {
    return false;
  }
  bytes_sent_ += 3;
  const MonotonicNs interval = config_.probe_interval_ns;
  char reply[32];
  std::size_t kept = 0;
  while (true) {
    if (port_.write_all("\r", deadline_ns, clock_) != PortIo::Ok) {
      return false;
    }
    ++bytes_sent_;
    const MonotonicNs now = clock_.now_ns();
    if (now >= deadline_ns) {
      return false;
    }
    std::size_t size = 0;
    const PortIo io = port_.read_line(reply + kept, sizeof reply - kept, size, std::min(deadline_ns, now + interval), clock_);
    bytes_received_ += size;
    kept += size;
    if (io == PortIo::TimedOut) {
      continue;
    }
    const ReplyParse parsed = parse_reply({reply, kept}, 'B');
    if (io != PortIo::Ok || parsed.status != ReplyStatus::Complete) {
      return false;
    }
    levels = static_cast<std::uint8_t>(parsed.value);
    return true;
  }
}

bool Cy545Link::force_outputs_off(MonotonicNs deadline_ns) {
  outputs_confirmed_off_ = false;
  running_ = false;  // whatever was under way: the query below waits for the chip itself
  std::uint8_t levels = 0;
  if (!read_user_bits_when_free(levels, deadline_ns)) {
    std::snprintf(last_error_, sizeof last_error_,
                  "the controller did not answer before the spindle-off and drivers-off commands: the spindle and "
                  "drivers may still be on; cut the mill's power");
    return false;
  }
  // The spindle's output latched off with the drivers already off (bit 0 is a level), then every bit
  // 0-5 low; each command on its own, so that none arrives while the chip takes the one before.
  CommandBytes commands[4]{};
  const bool built = bit_command(write_bits_code(false, false, config_.wiring.spindle_output, false), commands[0]) &&
                     bit_command(kWriteStrobeBit, commands[1]) && clear_bit_command(kWriteStrobeBit, commands[2]) &&
                     bit_command(write_bits_code(false, false, 0, false), commands[3]);
  for (const CommandBytes& command : commands) {
    if (!built || port_.write_all(command.view(), deadline_ns, clock_) != PortIo::Ok) {
      std::snprintf(last_error_, sizeof last_error_,
                    "the spindle-off and drivers-off commands could not be written to the port: the spindle and "
                    "drivers may still be on; cut the mill's power");
      return false;
    }
    bytes_sent_ += command.size;
    clock_.sleep_until_ns(clock_.now_ns() + config_.command_settle_ns);
  }
  if (!read_user_bits_when_free(levels, deadline_ns) || (levels & 0xBFU) != 0) {
    std::snprintf(last_error_, sizeof last_error_,
                  "the controller did not confirm its outputs off (\"? B\" %s): the spindle and drivers may still be "
                  "on; cut the mill's power",
                  (levels & 0xBFU) != 0 ? "reads bits still set" : "unanswered");
    return false;
  }
  outputs_confirmed_off_ = true;
  spindle_on_ = false;
  drivers_on_ = false;
  selected_channel_ = -1;
  return true;
}

bool Cy545Link::write_bytes(std::string_view bytes, MonotonicNs deadline_ns) {
  const PortIo io = port_.write_all(bytes, deadline_ns, clock_);
  bytes_sent_ += bytes.size();
  switch (io) {
    case PortIo::Ok:
      return true;
    case PortIo::Closed:
      latch_fault(MachineFault::PortClosed);
      return false;
    case PortIo::TimedOut:
    case PortIo::Failed:
      break;
  }
  latch_fault(MachineFault::WriteFailed);
  return false;
}

// Without CTS the host must give the chip time to take each command before the next (manual,
// chapter 16): the next command's first three bytes wait in its buffer, and the settle keeps the
// fourth from arriving while the chip still executes (see Cy545Config::command_settle_ns).
bool Cy545Link::send(const CommandBytes& command, MonotonicNs deadline_ns) {
  if (!wait_free(deadline_ns)) {
    return false;
  }
  if (quiet_until_ns_ > clock_.now_ns()) {
    clock_.sleep_until_ns(std::min(quiet_until_ns_, deadline_ns));
  }
  if (!write_bytes(command.view(), deadline_ns)) {
    return false;
  }
  quiet_until_ns_ = clock_.now_ns() + config_.command_settle_ns;
  return true;
}

bool Cy545Link::send_bits(std::uint8_t code, MonotonicNs deadline_ns) {
  CommandBytes command{};
  return bit_command(code, command) && send(command, deadline_ns);
}

bool Cy545Link::latch(MonotonicNs deadline_ns) {
  CommandBytes command{};
  return bit_command(kWriteStrobeBit, command) && send(command, deadline_ns) &&
         clear_bit_command(kWriteStrobeBit, command) && send(command, deadline_ns);
}

bool Cy545Link::latch_motor_line(std::uint8_t channel, bool on, MonotonicNs deadline_ns) {
  return send_bits(write_bits_code(true, on, channel, false), deadline_ns) && latch(deadline_ns);
}

// The old channel's line is latched off (data 0) before the new one's on (data 1): right whether the
// MMC-4S latches each line's data bit (two lines on would step two axes at once) or only the
// address (then the first strobe selects the old channel for a moment, with no step sent).
bool Cy545Link::select_channel(std::uint8_t channel, MonotonicNs deadline_ns) {
  if (selected_channel_ == channel && motor_line_on_ == channel && drivers_on_) {
    return true;
  }
  if (motor_line_on_ != channel) {
    if (config_.wiring.channel_lines_latch_data && motor_line_on_ >= 0 &&
        !latch_motor_line(static_cast<std::uint8_t>(motor_line_on_), false, deadline_ns)) {
      return false;
    }
    motor_line_on_ = -1;
    if (!latch_motor_line(channel, true, deadline_ns)) {
      return false;
    }
    motor_line_on_ = channel;
  } else if (!send_bits(write_bits_code(true, true, channel, false), deadline_ns)) {
    return false;  // the line is on already: only the drivers and the address bits to set again
  }
  drivers_on_ = true;
  selected_channel_ = channel;
  return true;
}

bool Cy545Link::query(char letter, std::uint32_t& value, MonotonicNs deadline_ns) {
  CommandBytes command{};
  if (!query_command(letter, command) || !wait_free(deadline_ns)) {
    return false;
  }
  port_.discard_input();
  if (!send(command, deadline_ns)) {
    return false;
  }
  const MonotonicNs reply_deadline = std::min(deadline_ns, clock_.now_ns() + config_.reply_timeout_ns);
  char reply[32];
  std::size_t size = 0;
  const PortIo io = port_.read_line(reply, sizeof reply, size, reply_deadline, clock_);
  bytes_received_ += size;
  if (io == PortIo::Closed) {
    latch_fault(MachineFault::PortClosed);
    return false;
  }
  const ReplyParse parsed = parse_reply({reply, size}, letter);
  if (io == PortIo::Ok && parsed.status == ReplyStatus::Complete) {
    value = parsed.value;
    return true;
  }
  if (parsed.status == ReplyStatus::Garbled || io == PortIo::Failed) {
    const unsigned byte = parsed.at < size ? static_cast<unsigned char>(reply[parsed.at]) : 0U;
    std::snprintf(last_error_, sizeof last_error_, "reply to \"? %c\": byte %zu is 0x%02X where %s was expected",
                  letter, parsed.at, byte, parsed.status == ReplyStatus::Garbled ? parsed.expected : "a reply");
    latch_fault(MachineFault::GarbledReply);
    return false;
  }
  std::snprintf(last_error_, sizeof last_error_, "no complete reply to \"? %c\" within %lld ms (%zu bytes)", letter,
                static_cast<long long>(config_.reply_timeout_ns / 1'000'000), size);
  latch_fault(MachineFault::Timeout);
  return false;
}

MachineResult Cy545Link::start(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (!port_.is_open()) {
    return fail(MachineFault::OpenFailed);
  }
  // Adaptive baud: carriage returns until the chip answers a query.
  bool answered = false;
  CommandBytes command{};
  for (int attempt = 0; attempt < config_.start_attempts && !answered; ++attempt) {
    if (clock_.now_ns() >= deadline_ns) {
      break;
    }
    // No stop taken here: whatever an earlier run left latched on (the spindle) is turned off only
    // once the chip answers, below; a stop asked meanwhile is taken after that.
    const PortIo io = port_.write_all("\r", deadline_ns, clock_);
    bytes_sent_ += 1;
    if (io == PortIo::Closed) {
      return fail(MachineFault::PortClosed);
    }
    port_.discard_input();
    if (!query_command('P', command) || port_.write_all(command.view(), deadline_ns, clock_) != PortIo::Ok) {
      return fail(MachineFault::WriteFailed);
    }
    bytes_sent_ += command.size;
    char reply[32];
    std::size_t size = 0;
    const MonotonicNs reply_deadline = std::min(deadline_ns, clock_.now_ns() + config_.reply_timeout_ns);
    const PortIo read = port_.read_line(reply, sizeof reply, size, reply_deadline, clock_);
    bytes_received_ += size;
    if (read == PortIo::Closed) {
      return fail(MachineFault::PortClosed);
    }
    answered = read == PortIo::Ok && parse_reply({reply, size}, 'P').status == ReplyStatus::Complete;
  }
  if (!answered) {
    std::snprintf(last_error_, sizeof last_error_,
                  "the controller never answered \"? P\" (%d attempts): check the cable and the baud rate; a chip "
                  "left in binary mode (mode register bit 7 clear) answers only after a power cycle",
                  config_.start_attempts);
    return fail(MachineFault::NoAnswer);
  }
  // Initialise: I clears the position and the chip's user bits, ASCII mode said explicitly, then
  // rates and no ramp.
  const bool initialised = bare_command('I', command) && send(command, deadline_ns) &&
                           number_command('O', kAsciiMode, 255, command) && send(command, deadline_ns) &&
                           number_command('R', config_.motion.step_rate, 27000, command) && send(command, deadline_ns) &&
                           number_command('F', config_.motion.step_rate, 27000, command) && send(command, deadline_ns) &&
                           number_command('S', 0, 255, command) && send(command, deadline_ns);
  if (!initialised) {
    return fault_ != MachineFault::None ? MachineResult{false, MachineRefusal::None, fault_}
                                        : refuse(MachineRefusal::DeadlineTooShort);
  }
  // Every motor channel's line off (which one a previous run left on is not known), the drivers off.
  for (std::uint8_t line = 0; line < 4; ++line) {
    if (!send_bits(write_bits_code(false, false, line, false), deadline_ns) || !latch(deadline_ns)) {
      return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
    }
  }
  motor_line_on_ = -1;
  // Every output to its safe value before anything moves, and read back: the board's latches keep
  // what the last run left (a spindle still turning after a crash), which neither "I" nor a new
  // program clears.
  if (!force_outputs_off(deadline_ns)) {
    return fail(MachineFault::NoAnswer);
  }
  position_register_ = 0;
  selected_channel_ = -1;
  drivers_on_ = false;
  spindle_on_ = false;
  homed_ = false;
  rate_sent_ = config_.motion.step_rate;
  if (abort_asked()) {  // asked while the chip woke or started: taken now the outputs are off
    state_ = MachineState::Stopped;
    std::snprintf(last_error_, sizeof last_error_, "start stopped as asked; spindle and drivers off");
    return refuse(MachineRefusal::Aborted);
  }
  state_ = MachineState::Ready;
  return {true, MachineRefusal::None, MachineFault::None};
}

MonotonicNs Cy545Link::homing_bound_ns() const {
  // Per axis: out of the switch's zone and the whole travel at the approach rate, then the slow
  // departure (at most two legs' worth of steps); every leg's commands and switch reads bounded by
  // three reply timeouts; three axes, and a margin. A bound, not an estimate: near home it is seconds.
  const MonotonicNs query_ns = 3 * config_.reply_timeout_ns;  // a leg's commands, the reads, their answers
  const std::int64_t fast_steps = config_.motion.home_switch_zone_steps + config_.motion.homing_travel_steps;
  const std::int64_t legs = fast_steps / std::max(config_.motion.homing_chunk_steps, 1) + 2;
  const std::int64_t slow_steps = std::max(config_.motion.homing_chunk_steps, 1) + config_.motion.homing_slack_steps;
  const MonotonicNs axis_ns = steps_time_ns(fast_steps, config_.motion.homing_rate) + legs * query_ns +
                              steps_time_ns(slow_steps, config_.motion.homing_slow_rate) +
                              slow_steps * (query_ns + config_.pace_margin_ns);
  return 3 * axis_ns + 10 * kSecond;
}

MachineResult Cy545Link::aborted(MonotonicNs deadline_ns) {
  static_cast<void>(force_outputs_off(deadline_ns));
  homed_ = false;
  state_ = fault_ == MachineFault::None ? MachineState::Stopped : MachineState::Fault;
  std::snprintf(last_error_, sizeof last_error_, "homing stopped as asked; %s",
                outputs_confirmed_off_ ? "spindle and drivers off" : "the outputs could not be confirmed off");
  return refuse(MachineRefusal::Aborted);
}

Cy545Link::SwitchReading Cy545Link::read_home_switch(std::size_t axis, MonotonicNs deadline_ns, int reads) {
  int closed = 0;
  for (int read = 0; read < reads; ++read) {
    std::uint8_t levels = 0;
    // The first read waits out the leg before it (the chip answers once it is free), the rest only a reply.
    const MonotonicNs from = running_ ? std::max(busy_bound_ns_, clock_.now_ns()) : clock_.now_ns();
    const MonotonicNs bound = std::min(deadline_ns, from + config_.reply_timeout_ns);
    running_ = false;
    if (!read_user_bits_when_free(levels, bound)) {
      std::snprintf(last_error_, sizeof last_error_, "homing axis %c: the controller did not answer \"? B\" within %lld ms",
                    "XYZ"[axis], static_cast<long long>(config_.reply_timeout_ns / 1'000'000));
      latch_fault(MachineFault::Timeout);
      return SwitchReading::Failed;
    }
    const bool level = (levels & 0x02U) != 0;  // user bit 1: the input mux, with the read strobe on
    closed += level == config_.wiring.home_switch_closed_level[axis] ? 1 : 0;
  }
  return closed == reads ? SwitchReading::Closed : closed == 0 ? SwitchReading::Open : SwitchReading::Bouncing;
}

bool Cy545Link::homing_leg(std::size_t axis, std::int32_t steps, std::uint32_t rate, MonotonicNs deadline_ns) {
  CommandBytes command{};
  // Homing takes minutes: the watchdog must not drop meanwhile. A heartbeat sent moved the address
  // lines and the read strobe: the home switch goes back on the input line.
  const MonotonicNs heartbeat_due = heartbeat_due_ns_;
  if (!keep_alive(deadline_ns).done) {
    return false;
  }
  if (heartbeat_due_ns_ != heartbeat_due && homing_input_ >= 0 &&
      !send_bits(write_bits_code(true, false, static_cast<std::uint8_t>(homing_input_), true), deadline_ns)) {
    return false;
  }
  if (rate != rate_sent_) {
    if (!number_command('R', rate, 27000, command) || !send(command, deadline_ns)) {
      return false;
    }
    rate_sent_ = rate;
  }
  const auto count = static_cast<std::uint32_t>(std::abs(steps));
  const std::int64_t chip_steps = static_cast<std::int64_t>(steps) * chip_sign(axis);  // the direction line's wiring
  if (!number_command('N', count, kMax24, command) || !send(command, deadline_ns) ||
      !bare_command(chip_steps > 0 ? '+' : '-', command) || !send(command, deadline_ns) || !bare_command('G', command) ||
      !send(command, deadline_ns)) {
    return false;
  }
  position_register_ = static_cast<std::uint32_t>(static_cast<std::int64_t>(position_register_) + chip_steps) & kMax24;
  const MonotonicNs leg = steps_time_ns(count, rate);
  started_running(leg, leg + config_.pace_margin_ns);
  return true;
}

// The approach runs toward the switch (-), the departure away from it (+): every axis's switch is
// closed below its home (the rig's facts: board/<rig>/), so the last steps of homing are + (home_approach()).
bool Cy545Link::home_axis(std::size_t axis, MonotonicNs deadline_ns) {
  const char name = "XYZ"[axis];
  if (!select_channel(config_.wiring.motor_channel[axis], deadline_ns) ||
      !send_bits(write_bits_code(true, false, config_.wiring.home_input[axis], true), deadline_ns)) {
    return false;
  }
  selected_channel_ = -1;  // the address lines now carry the input's number
  homing_input_ = config_.wiring.home_input[axis];
  const std::int32_t chunk = std::max(config_.motion.homing_chunk_steps, 1);
  const int debounce = std::max(config_.homing_debounce_reads, 1);
  // Before anything moves: a closed switch means the axis is inside its zone; leave it first.
  SwitchReading reading = read_home_switch(axis, deadline_ns, debounce);
  for (std::int32_t left = 0; reading != SwitchReading::Open; left += chunk) {
    if (reading == SwitchReading::Failed || abort_asked()) {
      return false;
    }
    if (left >= config_.motion.home_switch_zone_steps) {
      std::snprintf(last_error_, sizeof last_error_,
                    "homing axis %c: its home switch still reads closed %d steps out of its zone: check its wiring and "
                    "the closed level in the configuration",
                    name, left);
      latch_fault(MachineFault::PositionMismatch);
      return false;
    }
    if (!homing_leg(axis, chunk, config_.motion.homing_rate, deadline_ns)) {
      return false;
    }
    reading = read_home_switch(axis, deadline_ns, debounce);
  }
  // The approach: until the switch reads anything but open (closed, or bouncing at its edge).
  for (std::int32_t travelled = 0; reading == SwitchReading::Open; travelled += chunk) {
    if (abort_asked()) {
      return false;
    }
    if (travelled >= config_.motion.homing_travel_steps) {
      std::snprintf(last_error_, sizeof last_error_,
                    "homing axis %c: no home switch within %d steps of travel moving -: check its step direction "
                    "(machine.board.step_direction: a motor that runs the other way never reaches it), the switch, "
                    "its wiring and its closed level in the configuration",
                    name, travelled);
      latch_fault(MachineFault::PositionMismatch);
      return false;
    }
    if (!homing_leg(axis, -chunk, config_.motion.homing_rate, deadline_ns)) {
      return false;
    }
    reading = read_home_switch(axis, deadline_ns, debounce);
  }
  if (reading == SwitchReading::Failed) {
    return false;
  }
  // The departure, one slow step at a time with a read after each, until a read says open and the
  // debounce's reads agree: that edge is home. (A bouncing switch can end it early by at most its
  // bouncing band: the repeatability of home, measured in the tests.)
  for (std::int32_t stepped = 0; reading != SwitchReading::Open; ++stepped) {
    if (reading == SwitchReading::Failed || abort_asked()) {
      return false;
    }
    if (stepped >= chunk + config_.motion.homing_slack_steps) {
      std::snprintf(last_error_, sizeof last_error_, "homing axis %c: its home switch did not settle open within %d steps",
                    name, stepped);
      latch_fault(MachineFault::PositionMismatch);
      return false;
    }
    if (!homing_leg(axis, 1, config_.motion.homing_slow_rate, deadline_ns)) {
      return false;
    }
    reading = read_home_switch(axis, deadline_ns, 1);
    if (reading == SwitchReading::Open) {
      reading = read_home_switch(axis, deadline_ns, debounce);
    }
  }
  return true;
}

MachineResult Cy545Link::home(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  if (!is_permutation(config_.motion.homing_order)) {
    std::snprintf(last_error_, sizeof last_error_, "homing refused: the homing order names each axis once");
    return refuse(MachineRefusal::BadTarget);
  }
  if (deadline_ns - clock_.now_ns() < homing_bound_ns()) {
    std::snprintf(last_error_, sizeof last_error_, "homing refused: %.0f s given, it can take up to %.0f s",
                  static_cast<double>(deadline_ns - clock_.now_ns()) / 1e9, static_cast<double>(homing_bound_ns()) / 1e9);
    return refuse(MachineRefusal::DeadlineTooShort);  // nothing sent: homing could outlast the bound
  }
  // In the configured order, Z first (the configuration refuses any other: Cy545Motion::homing_order).
  for (const std::uint8_t axis : config_.motion.homing_order) {
    if (!home_axis(axis, deadline_ns)) {
      if (fault_ == MachineFault::None && abort_asked()) {
        return aborted(deadline_ns);
      }
      return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
    }
    // This axis's edge is its zero; the register is shared, so each axis is zeroed in turn.
    CommandBytes zero{};
    if (!number_command('A', 0, kMax24, zero) || !send(zero, deadline_ns)) {
      return {false, MachineRefusal::None, fault_};
    }
    position_register_ = 0;
  }
  homing_input_ = -1;
  // Read strobe off, the moving rate back, then the position must be the home's.
  CommandBytes command{};
  std::uint32_t position = 1;
  if (!send_bits(write_bits_code(true, false, config_.wiring.motor_channel[0], false), deadline_ns) ||
      !number_command('R', config_.motion.step_rate, 27000, command) || !send(command, deadline_ns) ||
      !query('P', position, deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  rate_sent_ = config_.motion.step_rate;
  if (position != 0) {
    std::snprintf(last_error_, sizeof last_error_, "after homing the controller reports position %u, not 0", position);
    return fail(MachineFault::PositionMismatch);
  }
  position_register_ = 0;
  commanded_ = {0, 0, 0};
  homed_ = true;
  state_ = MachineState::Homed;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult Cy545Link::declare_home(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  CommandBytes command{};
  if (!number_command('A', 0, kMax24, command) || !send(command, deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  position_register_ = 0;
  commanded_ = {0, 0, 0};
  homed_ = true;
  state_ = MachineState::Homed;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult Cy545Link::move(const MachineTarget& target, MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Held) {
    return refuse(MachineRefusal::Held);
  }
  if (!homed_ || state_ != MachineState::Homed) {
    return refuse(MachineRefusal::NotHomed);
  }
  if (target.cutting && !spindle_on_) {
    return refuse(MachineRefusal::SpindleOff);
  }
  if (!is_permutation(target.order)) {
    return refuse(MachineRefusal::BadTarget);
  }
  std::int64_t total = 0;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (std::abs(static_cast<std::int64_t>(target.motor_steps[axis])) > static_cast<std::int64_t>(kMax24 / 2)) {
      return refuse(MachineRefusal::BadTarget);
    }
    total += std::abs(static_cast<std::int64_t>(target.motor_steps[axis]) - commanded_[axis]);
  }
  const MonotonicNs duration = steps_time_ns(total, config_.motion.step_rate);
  if (static_cast<double>(duration) > config_.motion.update_period_s * 1.05 * static_cast<double>(kSecond)) {
    return refuse(MachineRefusal::TooLong);  // a hold must take effect within one update
  }
  if (deadline_ns - clock_.now_ns() < duration + 3 * config_.pace_margin_ns) {
    return refuse(MachineRefusal::DeadlineTooShort);
  }
  CommandBytes command{};
  for (const std::uint8_t axis : target.order) {
    const std::int64_t delta = static_cast<std::int64_t>(target.motor_steps[axis]) - commanded_[axis];
    if (delta == 0) {
      continue;
    }
    const auto steps = static_cast<std::uint32_t>(std::abs(delta));
    const std::int64_t chip_delta = delta * chip_sign(axis);  // the direction line's wiring
    if (!select_channel(config_.wiring.motor_channel[axis], deadline_ns) ||
        !number_command('N', steps, kMax24, command) || !send(command, deadline_ns) ||
        !bare_command(chip_delta > 0 ? '+' : '-', command) || !send(command, deadline_ns) ||
        !bare_command('G', command) || !send(command, deadline_ns)) {
      return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
    }
    commanded_[axis] = target.motor_steps[axis];
    position_register_ = static_cast<std::uint32_t>(static_cast<std::int64_t>(position_register_) + chip_delta) & kMax24;
    const MonotonicNs leg = steps_time_ns(steps, config_.motion.step_rate);
    started_running(leg, leg + config_.pace_margin_ns);
  }
  ++moves_done_;
  // Done when the last leg has run: the next update starts from a free chip.
  if (!wait_free(deadline_ns)) {
    return refuse(MachineRefusal::DeadlineTooShort);
  }
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult Cy545Link::verify(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  std::uint32_t position = 0;
  if (!query('P', position, deadline_ns)) {
    return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
  }
  if (position != position_register_) {
    std::snprintf(last_error_, sizeof last_error_, "the controller reports position %u, %u was commanded", position,
                  position_register_);
    return fail(MachineFault::PositionMismatch);
  }
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult Cy545Link::set_spindle(bool on, MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  if (!send_bits(write_bits_code(drivers_on_, on, config_.wiring.spindle_output, false), deadline_ns) || !latch(deadline_ns)) {
    return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
  }
  selected_channel_ = -1;  // the address lines were the spindle output's
  spindle_on_ = on;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult Cy545Link::keep_alive(MonotonicNs deadline_ns) {
  if (config_.wiring.heartbeat_output < 0) {
    return {true, MachineRefusal::None, MachineFault::None};
  }
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  if (clock_.now_ns() < heartbeat_due_ns_) {
    return {true, MachineRefusal::None, MachineFault::None};
  }
  const auto port = static_cast<std::uint8_t>(config_.wiring.heartbeat_output);
  if (!send_bits(write_bits_code(drivers_on_, !heartbeat_level_, port, false), deadline_ns) || !latch(deadline_ns)) {
    return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
  }
  selected_channel_ = -1;  // the address lines were the heartbeat output's (the motor line stays latched)
  heartbeat_level_ = !heartbeat_level_;
  heartbeat_due_ns_ = clock_.now_ns() + config_.wiring.heartbeat_period_ns / 2;
  return {true, MachineRefusal::None, MachineFault::None};
}

void Cy545Link::hold() {
  if (state_ == MachineState::Homed) {
    before_hold_ = state_;
    state_ = MachineState::Held;
  }
}

void Cy545Link::resume() {
  if (state_ == MachineState::Held) {
    state_ = before_hold_;
  }
}

MachineResult Cy545Link::stop(MonotonicNs deadline_ns) {
  hold();
  homed_ = false;  // limp axes may have moved: home again
  // Whatever fault is latched: it says the line misbehaved, not that the chip stopped listening, and a
  // spindle left turning is the worst way for a stop to end.
  if (!force_outputs_off(deadline_ns)) {
    if (fault_ == MachineFault::None) {
      latch_fault(MachineFault::Timeout);
    }
    return {false, MachineRefusal::None, fault_};
  }
  if (fault_ == MachineFault::None) {
    state_ = MachineState::Stopped;
  }
  return {true, MachineRefusal::None, fault_};
}

MachineStatus Cy545Link::status() const {
  return {state_,    fault_,      commanded_,  homed_,         spindle_on_,
          drivers_on_, moves_done_, bytes_sent_, bytes_received_};
}

}  // namespace stencil::hal::cy545
