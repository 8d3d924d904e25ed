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

bool Cy545Link::send(const CommandBytes& command, MonotonicNs deadline_ns) {
  return wait_free(deadline_ns) && write_bytes(command.view(), deadline_ns);
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

bool Cy545Link::select_channel(std::uint8_t channel, MonotonicNs deadline_ns) {
  if (selected_channel_ == channel && drivers_on_) {
    return true;
  }
  if (!send_bits(write_bits_code(true, false, channel, false), deadline_ns) || !latch(deadline_ns)) {
    return false;
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
    std::snprintf(last_error_, sizeof last_error_, "the controller never answered \"? P\" (%d attempts)",
                  config_.start_attempts);
    return fail(MachineFault::NoAnswer);
  }
  // Initialise: I clears the position and the user bits (drivers off), then rates, no ramp, mode 0.
  const bool initialised = bare_command('I', command) && send(command, deadline_ns) &&
                           number_command('R', config_.step_rate, 27000, command) && send(command, deadline_ns) &&
                           number_command('F', config_.step_rate, 27000, command) && send(command, deadline_ns) &&
                           number_command('S', 0, 255, command) && send(command, deadline_ns) &&
                           number_command('O', 0, 255, command) && send(command, deadline_ns);
  if (!initialised) {
    return fault_ != MachineFault::None ? MachineResult{false, MachineRefusal::None, fault_}
                                        : refuse(MachineRefusal::DeadlineTooShort);
  }
  position_register_ = 0;
  selected_channel_ = -1;
  drivers_on_ = false;
  spindle_on_ = false;
  homed_ = false;
  state_ = MachineState::Ready;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult Cy545Link::home(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  const MonotonicNs seek = steps_time_ns(config_.homing_travel_steps, config_.homing_rate) + config_.pace_margin_ns;
  if (deadline_ns - clock_.now_ns() < 3 * seek + 4 * config_.reply_timeout_ns) {
    return refuse(MachineRefusal::DeadlineTooShort);  // nothing sent: the seeks could outlast the bound
  }
  CommandBytes command{};
  if (!number_command('F', config_.homing_rate, 27000, command) || !send(command, deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  // Z first: after a crash or a stop mid-cut the tool may stand in the stock, and only raising it
  // first takes it out without ploughing sideways through the work.
  for (const std::size_t axis : {std::size_t{2}, std::size_t{0}, std::size_t{1}}) {
    // The axis's channel, its switch on the input line, then the seek (busy for an unknown time up
    // to the longest travel: nothing is sent until that has passed).
    if (!select_channel(config_.motor_channel[axis], deadline_ns) ||
        !send_bits(write_bits_code(true, false, config_.home_input[axis], true), deadline_ns) ||
        !home_command(kHomeOnInputOpen, command) || !send(command, deadline_ns)) {
      return {false, MachineRefusal::None, fault_};
    }
    selected_channel_ = -1;  // the address lines now carry the input's number
    position_register_ = 0;  // where the seek leaves it
    started_running(0, seek);
  }
  // Read strobe off, rates back, then the position must be the home's.
  std::uint32_t position = 1;
  if (!send_bits(write_bits_code(true, false, config_.motor_channel[0], false), deadline_ns) ||
      !number_command('F', config_.step_rate, 27000, command) || !send(command, deadline_ns) ||
      !query('P', position, deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
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
  const MonotonicNs duration = steps_time_ns(total, config_.step_rate);
  if (static_cast<double>(duration) > config_.update_period_s * 1.05 * static_cast<double>(kSecond)) {
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
    if (!select_channel(config_.motor_channel[axis], deadline_ns) ||
        !number_command('N', steps, kMax24, command) || !send(command, deadline_ns) ||
        !bare_command(delta > 0 ? '+' : '-', command) || !send(command, deadline_ns) ||
        !bare_command('G', command) || !send(command, deadline_ns)) {
      return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
    }
    commanded_[axis] = target.motor_steps[axis];
    position_register_ = static_cast<std::uint32_t>(static_cast<std::int64_t>(position_register_) + delta) & kMax24;
    const MonotonicNs leg = steps_time_ns(steps, config_.step_rate);
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
  if (!send_bits(write_bits_code(drivers_on_, on, config_.spindle_output, false), deadline_ns) || !latch(deadline_ns)) {
    return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
  }
  selected_channel_ = -1;  // the address lines were the spindle output's
  spindle_on_ = on;
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
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  // Spindle off (its output latched with the drivers still on), then every bit 0-5 low: drivers off.
  const bool spindle_off = send_bits(write_bits_code(true, false, config_.spindle_output, false), deadline_ns) &&
                           latch(deadline_ns);
  if (!spindle_off || !send_bits(write_bits_code(false, false, 0, false), deadline_ns)) {
    return {false, fault_ == MachineFault::None ? MachineRefusal::DeadlineTooShort : MachineRefusal::None, fault_};
  }
  spindle_on_ = false;
  drivers_on_ = false;
  selected_channel_ = -1;
  homed_ = false;  // limp axes may have moved: home again
  state_ = MachineState::Stopped;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineStatus Cy545Link::status() const {
  return {state_,    fault_,      commanded_,  homed_,         spindle_on_,
          drivers_on_, moves_done_, bytes_sent_, bytes_received_};
}

}  // namespace stencil::hal::cy545
