// LinuxcncLink: see the header. Every call returns by its deadline: each exchange waits on the socket
// at most until the earlier of the call's deadline and the reply timeout.
#include "hal/linuxcnc/linuxcnc_link.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "hal/linuxcnc/linuxcncrsh_replies.hpp"

namespace stencil::hal::linuxcnc {
namespace {

std::string_view text_of(const std::array<char, 32>& field) {
  return {field.data(), ::strnlen(field.data(), field.size())};
}

constexpr int kMaxErrorsAtOnce = 8;  // "get error" asked until "ERROR OK", at most this often

}  // namespace

std::string_view check_linuxcnc_config(const LinuxcncConfig& config) {
  const std::string_view connect = text_of(config.connect_password);
  const std::string_view enable = text_of(config.enable_password);
  if (connect.empty() || enable.empty()) {
    return "linuxcncrsh's connect and enable passwords must be set (linuxcncrsh --connectpw and --enablepw in LinuxCNC's INI)";
  }
  if (connect == kDefaultConnectPassword || enable == kDefaultEnablePassword) {
    return "linuxcncrsh's default passwords (EMC, EMCTOO) are refused: linuxcncrsh listens on every network interface, "
           "so give it passwords of its own (--connectpw, --enablepw in LinuxCNC's INI) and set them here";
  }
  // linuxcncrsh keeps at most 15 characters of a password (sim/linuxcnc_mill/README.md): a longer
  // one would never match what it keeps.
  if (connect.size() > kMaxPasswordLength || enable.size() > kMaxPasswordLength ||
      connect.find_first_of(" \t\r\n") != std::string_view::npos || enable.find_first_of(" \t\r\n") != std::string_view::npos) {
    return "a linuxcncrsh password must be one word (no spaces), at most 15 characters (linuxcncrsh's own limit)";
  }
  in_addr parsed{};
  if (::strnlen(config.address.data(), config.address.size()) == config.address.size() ||
      ::inet_pton(AF_INET, config.address.data(), &parsed) != 1) {
    return "the LinuxCNC address must be IPv4 digits (127.0.0.1 when LinuxCNC runs on this box)";
  }
  if (config.port == 0) {
    return "the linuxcncrsh port must be 1 to 65535";
  }
  if (!(config.steps_per_mm > 0.0) || !(config.max_move_mm > 0.0) || !(config.feed_mm_per_min > 0.0) ||
      !(config.position_tolerance_mm > 0.0)) {
    return "steps_per_mm, the longest move, the feed and the position tolerance must be positive";
  }
  for (const double travel : config.travel_mm) {
    if (!(travel > 0.0)) {
      return "every axis's travel must be positive";
    }
  }
  return {};
}

LinuxcncLink::LinuxcncLink(Clock& clock, const LinuxcncConfig& config)
    : clock_(clock), config_(config), channel_(clock) {}

void LinuxcncLink::note_error(std::string_view what, std::string_view words) {
  if (words.empty()) {
    std::snprintf(last_error_.data(), last_error_.size(), "%.*s", static_cast<int>(what.size()), what.data());
  } else {
    std::snprintf(last_error_.data(), last_error_.size(), "%.*s: LinuxCNC says \"%.*s\"", static_cast<int>(what.size()),
                  what.data(), static_cast<int>(words.size()), words.data());
  }
}

MachineResult LinuxcncLink::fail(MachineFault fault, std::string_view what, std::string_view words) {
  if (fault_ == MachineFault::None) {  // the first fault's words are the reason
    note_error(what, words);
    fault_ = fault;
  }
  state_ = MachineState::Fault;
  return {false, MachineRefusal::None, fault};
}

MachineResult LinuxcncLink::refuse(MachineRefusal refusal) const { return {false, refusal, MachineFault::None}; }

bool LinuxcncLink::exchange(std::string_view line, MonotonicNs deadline_ns, std::string_view& reply) {
  const MonotonicNs bound_ns = std::min(deadline_ns, clock_.now_ns() + config_.reply_timeout_ns);
  LineStatus sent = channel_.send_line(line, bound_ns);
  LineStatus got = sent == LineStatus::Ok ? channel_.read_line(reply, bound_ns) : sent;
  if (got == LineStatus::Ok) {
    return true;
  }
  std::array<char, 160> what{};
  const int shown = static_cast<int>(std::min<std::size_t>(line.size(), 48));
  const char* word = line.substr(0, 11) == "set enable " || line.substr(0, 6) == "hello " ? "(a password)" : nullptr;
  switch (got) {
    case LineStatus::Timeout:
      std::snprintf(what.data(), what.size(), "linuxcncrsh did not answer \"%.*s\" in time", word ? 12 : shown,
                    word ? word : line.data());
      static_cast<void>(fail(MachineFault::Timeout, what.data()));
      break;
    case LineStatus::Closed:
      static_cast<void>(fail(MachineFault::PortClosed, "the connection to linuxcncrsh closed (LinuxCNC stopped, or crashed)"));
      break;
    default:
      std::snprintf(what.data(), what.size(), "the connection to linuxcncrsh failed: %s", std::strerror(channel_.last_errno()));
      static_cast<void>(fail(MachineFault::WriteFailed, what.data()));
      break;
  }
  channel_.close();
  return false;
}

bool LinuxcncLink::set(std::string_view command, std::string_view name, MonotonicNs deadline_ns) {
  std::string_view reply;
  if (!exchange(command, deadline_ns, reply)) {
    return false;
  }
  const SetReply answer = set_reply(reply, name);
  if (answer == SetReply::Ack) {
    return true;
  }
  std::array<char, 160> what{};
  std::snprintf(what.data(), what.size(), "LinuxCNC refused \"set %.*s\"", static_cast<int>(name.size()), name.data());
  static_cast<void>(fail(answer == SetReply::Nak ? MachineFault::CommandRefused : MachineFault::GarbledReply, what.data(), reply));
  return false;
}

bool LinuxcncLink::get(std::string_view what, MonotonicNs deadline_ns, std::string_view& reply) {
  std::array<char, 64> line{};
  std::snprintf(line.data(), line.size(), "get %.*s", static_cast<int>(what.size()), what.data());
  return exchange(line.data(), deadline_ns, reply);
}

bool LinuxcncLink::await_value(std::string_view what, std::string_view key, std::string_view expected,
                               MonotonicNs deadline_ns, std::string_view& reply) {
  // A set is ACKed once LinuxCNC's task has received it; its status shows the result a few task
  // cycles later (ESTOP ON for up to tens of ms after "SET ESTOP ACK", measured).
  const MonotonicNs until_ns = std::min(deadline_ns, clock_.now_ns() + config_.status_settle_ns);
  for (;;) {
    if (!get(what, deadline_ns, reply)) {
      return false;
    }
    if (value_of(reply, key) == expected || clock_.now_ns() + 10'000'000 >= until_ns) {
      return true;
    }
    clock_.sleep_until_ns(clock_.now_ns() + 10'000'000);
  }
}

bool LinuxcncLink::check_errors(MonotonicNs deadline_ns, bool drop) {
  for (int i = 0; i < kMaxErrorsAtOnce; ++i) {
    std::string_view reply;
    if (!get("error", deadline_ns, reply)) {
      return false;
    }
    std::string_view words;
    const ErrorReply error = parse_error(reply, words);
    if (error == ErrorReply::None) {
      return true;
    }
    if (error == ErrorReply::Other) {
      static_cast<void>(fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get error\" did not parse", reply));
      return false;
    }
    // "Note: ..." is LinuxCNC telling, not failing ("Note: Motion enabled after reaching a coordinate
    // soft limit with active external offsets" comes with every machine on after an off).
    if (!drop && !(words.size() >= 6 && std::memcmp(words.data(), "Note: ", 6) == 0)) {
      static_cast<void>(fail(MachineFault::ControllerError, "LinuxCNC reported an error", words));
      return false;
    }
  }
  return true;  // still more: a flood of stale errors at start-up; the next look reads on
}

bool LinuxcncLink::check_health(MonotonicNs deadline_ns) {
  std::string_view reply;
  if (!get("estop", deadline_ns, reply)) {
    return false;
  }
  const std::string_view estop = value_of(reply, "ESTOP");
  if (estop == "ON") {
    // The reason it went there, when LinuxCNC gave one, is better than "ESTOP ON".
    std::string_view error;
    if (get("error", deadline_ns, error) && parse_error(error, error) == ErrorReply::Error) {
      static_cast<void>(fail(MachineFault::EstopPressed, "LinuxCNC is in e-stop", error));
    } else {
      static_cast<void>(fail(MachineFault::EstopPressed, "LinuxCNC is in e-stop", "ESTOP ON"));
    }
    return false;
  }
  if (estop != "OFF") {
    static_cast<void>(fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get estop\" did not parse", reply));
    return false;
  }
  if (!check_errors(deadline_ns, false)) {
    return false;
  }
  if (!machine_on_) {
    return true;
  }
  if (!get("machine", deadline_ns, reply)) {
    return false;
  }
  const std::string_view machine = value_of(reply, "MACHINE");
  if (machine == "OFF") {
    static_cast<void>(fail(MachineFault::ControllerError, "LinuxCNC turned its machine off", "MACHINE OFF"));
    return false;
  }
  if (machine != "ON") {
    static_cast<void>(fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get machine\" did not parse", reply));
    return false;
  }
  return true;
}

bool LinuxcncLink::read_position(MonotonicNs deadline_ns) {
  std::string_view reply;
  if (!get("abs_act_pos", deadline_ns, reply)) {
    return false;
  }
  if (!parse_xyz(reply, "ABS_ACT_POS", actual_mm_)) {
    static_cast<void>(fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get abs_act_pos\" did not parse", reply));
    return false;
  }
  return true;
}

bool LinuxcncLink::update_moves_done(MonotonicNs deadline_ns) {
  std::string_view reply;
  if (!get("program_status", deadline_ns, reply)) {
    return false;
  }
  const std::string_view program = value_of(reply, "PROGRAM_STATUS");
  if (program == "IDLE") {
    moves_done_ = moves_sent_;
  } else if (program == "RUNNING" || program == "PAUSED") {
    // The newest is still moving; the earlier ones each lasted at most an update.
    moves_done_ = std::max(moves_done_, moves_sent_ > 0 ? moves_sent_ - 1 : 0);
  } else {
    static_cast<void>(fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get program_status\" did not parse", reply));
    return false;
  }
  return true;
}

MachineResult LinuxcncLink::start(MonotonicNs deadline_ns) {
  fault_ = MachineFault::None;
  last_error_[0] = '\0';
  homed_ = false;
  spindle_on_ = false;
  machine_on_ = false;
  const std::string_view problem = check_linuxcnc_config(config_);
  if (!problem.empty()) {
    return fail(MachineFault::OpenFailed, problem);
  }
  const LineStatus connected =
      channel_.connect(config_.address.data(), config_.port, std::min(deadline_ns, clock_.now_ns() + config_.reply_timeout_ns));
  if (connected != LineStatus::Ok) {
    std::array<char, 200> what{};
    std::snprintf(what.data(), what.size(), "nothing answers at %s port %u (is LinuxCNC running, with DISPLAY = linuxcncrsh?): %s",
                  config_.address.data(), static_cast<unsigned>(config_.port),
                  connected == LineStatus::Timeout ? "no answer in time" : std::strerror(channel_.last_errno()));
    return fail(MachineFault::NoAnswer, what.data());
  }
  state_ = MachineState::Open;
  std::string_view reply;
  std::snprintf(command_.data(), command_.size(), "hello %s stencil 1.1", config_.connect_password.data());
  if (!exchange(command_.data(), deadline_ns, reply)) {
    return {false, MachineRefusal::None, fault_};
  }
  if (!hello_accepted(reply)) {
    return fail(MachineFault::CommandRefused, "linuxcncrsh refused the connect password", reply);
  }
  // Echo is on at first: "set echo off" comes back as itself; verbose on makes every set answer.
  if (!exchange("set echo off", deadline_ns, reply) || !set("set verbose on", "VERBOSE", deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  std::snprintf(command_.data(), command_.size(), "set enable %s", config_.enable_password.data());
  if (!set(command_.data(), "ENABLE", deadline_ns) || !check_errors(deadline_ns, true)) {
    return {false, MachineRefusal::None, fault_};
  }
  // A stop asked while starting is taken once connected: LinuxCNC keeps nothing running across a
  // client's start (the machine stays off until turned on below).
  if (abort_asked()) {
    static_cast<void>(stop(deadline_ns));
    return refuse(MachineRefusal::Aborted);
  }
  if (!set("set estop off", "ESTOP", deadline_ns) || !await_value("estop", "ESTOP", "OFF", deadline_ns, reply)) {
    return {false, MachineRefusal::None, fault_};
  }
  if (value_of(reply, "ESTOP") != "OFF") {
    return fail(MachineFault::EstopPressed, "LinuxCNC stays in e-stop after \"set estop off\" (is its e-stop button pressed?)", reply);
  }
  if (!set("set machine on", "MACHINE", deadline_ns) || !await_value("machine", "MACHINE", "ON", deadline_ns, reply)) {
    return {false, MachineRefusal::None, fault_};
  }
  if (value_of(reply, "MACHINE") != "ON") {
    return fail(MachineFault::ControllerError, "LinuxCNC's machine did not turn on", reply);
  }
  machine_on_ = true;
  if (!set("set spindle off", "SPINDLE", deadline_ns) || !check_health(deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  state_ = MachineState::Ready;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult LinuxcncLink::home(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  homed_ = false;
  if (!machine_on_) {  // after a stop: on again first
    std::string_view reply;
    if (!set("set machine on", "MACHINE", deadline_ns) || !await_value("machine", "MACHINE", "ON", deadline_ns, reply)) {
      return {false, MachineRefusal::None, fault_};
    }
    if (value_of(reply, "MACHINE") != "ON") {
      return fail(MachineFault::ControllerError, "LinuxCNC's machine did not turn on", reply);
    }
    machine_on_ = true;
  }
  // LinuxCNC's homing sequence (the INI's HOME_SEQUENCE: Z first on sim/linuxcnc_mill), in joint
  // mode ("must be in joint mode to home" otherwise). LinuxCNC keeps its joints homed across machine
  // off and on (not across its e-stop): then its homing stands, and nothing moves.
  std::string_view reply;
  std::array<bool, 3> homed{};
  if (!set("set mode manual", "MODE", deadline_ns) || !get("joint_homed", deadline_ns, reply)) {
    return {false, MachineRefusal::None, fault_};
  }
  if (!parse_joints_homed(reply, homed)) {
    return fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get joint_homed\" did not parse", reply);
  }
  if (!(homed[0] && homed[1] && homed[2]) &&
      (!set("set teleop_enable off", "TELEOP_ENABLE", deadline_ns) || !set("set home -1", "HOME", deadline_ns))) {
    return {false, MachineRefusal::None, fault_};
  }
  for (;;) {
    if (abort_asked()) {
      static_cast<void>(stop(deadline_ns));
      return refuse(MachineRefusal::Aborted);
    }
    if (!check_health(deadline_ns) || !get("joint_homed", deadline_ns, reply)) {
      return {false, MachineRefusal::None, fault_};
    }
    if (!parse_joints_homed(reply, homed)) {
      return fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get joint_homed\" did not parse", reply);
    }
    if (homed[0] && homed[1] && homed[2]) {
      break;
    }
    if (clock_.now_ns() + config_.homing_poll_ns >= deadline_ns) {
      return fail(MachineFault::Timeout, "LinuxCNC did not finish homing in time", reply);
    }
    clock_.sleep_until_ns(clock_.now_ns() + config_.homing_poll_ns);
  }
  // Exact path: LinuxCNC blends corners otherwise, and only the straight segment was checked.
  if (!set("set mode mdi", "MODE", deadline_ns) || !set("set mdi G21 G90 G94 G17 G40 G49 G54 G61", "MDI", deadline_ns) ||
      !check_errors(deadline_ns, false) || !read_position(deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  // Homing that stood (LinuxCNC kept it) leaves the mill where it stopped: it goes home as homing
  // would, Z first (the tool up out of the stock, then across), at rapid.
  const bool away = std::fabs(actual_mm_[0]) > 1e-4 || std::fabs(actual_mm_[1]) > 1e-4 || std::fabs(actual_mm_[2]) > 1e-4;
  if (away && (!set("set mdi G53 G0 Z0", "MDI", deadline_ns) || !set("set mdi G53 G0 X0 Y0", "MDI", deadline_ns))) {
    return {false, MachineRefusal::None, fault_};
  }
  if (away && !await_home(deadline_ns)) {
    if (abort_asked()) {
      static_cast<void>(stop(deadline_ns));
      return refuse(MachineRefusal::Aborted);
    }
    return {false, MachineRefusal::None, fault_};
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const double steps = std::round(actual_mm_[i] * config_.steps_per_mm);
    if (!(std::fabs(steps) <= 2e9)) {
      return fail(MachineFault::PositionMismatch, "LinuxCNC's position after homing is out of range");
    }
    commanded_[i] = static_cast<std::int32_t>(steps);
  }
  if (commanded_ != std::array<std::int32_t, 3>{0, 0, 0}) {
    return fail(MachineFault::PositionMismatch, "LinuxCNC's position after homing is not its home (0, 0, 0)");
  }
  moves_done_ = moves_sent_;
  homed_ = true;
  state_ = MachineState::Homed;
  return {true, MachineRefusal::None, MachineFault::None};
}

bool LinuxcncLink::await_home(MonotonicNs deadline_ns) {
  for (;;) {
    if (abort_asked()) {
      return false;
    }
    std::string_view reply;
    if (!check_health(deadline_ns) || !get("program_status", deadline_ns, reply)) {
      return false;
    }
    if (value_of(reply, "PROGRAM_STATUS") == "IDLE") {
      if (!read_position(deadline_ns)) {
        return false;
      }
      if (std::fabs(actual_mm_[0]) <= 1e-4 && std::fabs(actual_mm_[1]) <= 1e-4 && std::fabs(actual_mm_[2]) <= 1e-4) {
        return true;
      }
    }
    if (clock_.now_ns() + config_.homing_poll_ns >= deadline_ns) {
      static_cast<void>(fail(MachineFault::Timeout, "LinuxCNC did not get back home in time", reply));
      return false;
    }
    clock_.sleep_until_ns(clock_.now_ns() + config_.homing_poll_ns);
  }
}

MachineResult LinuxcncLink::move(const MachineTarget& target, MonotonicNs deadline_ns) {
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
  std::array<double, 3> to{};
  for (std::size_t i = 0; i < 3; ++i) {
    to[i] = mm_of(target.motor_steps[i]);
    if (!(to[i] >= 0.0 && to[i] <= config_.travel_mm[i])) {
      return refuse(MachineRefusal::BadTarget);
    }
    if (std::fabs(to[i] - mm_of(commanded_[i])) > config_.max_move_mm) {
      return refuse(MachineRefusal::TooLong);
    }
  }
  std::snprintf(command_.data(), command_.size(), "set mdi G1 X%.6f Y%.6f Z%.6f F%.1f", to[0], to[1], to[2],
                config_.feed_mm_per_min);
  if (!set(command_.data(), "MDI", deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  commanded_ = target.motor_steps;
  ++moves_sent_;
  // A line LinuxCNC refuses is still ACKed: its refusal is an error, read now or at the next look.
  if (!check_errors(deadline_ns, false)) {
    return {false, MachineRefusal::None, fault_};
  }
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult LinuxcncLink::verify(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (!homed_) {
    return refuse(MachineRefusal::NotHomed);
  }
  if (!check_health(deadline_ns) || !update_moves_done(deadline_ns) || !compare_at_rest(deadline_ns, true)) {
    return {false, MachineRefusal::None, fault_};
  }
  return {true, MachineRefusal::None, MachineFault::None};
}

bool LinuxcncLink::compare_at_rest(MonotonicNs deadline_ns, bool actual_too) {
  if (moves_done_ != moves_sent_) {
    at_rest_short_ = 0;
    return true;  // still moving: compared once at rest
  }
  std::string_view reply;
  std::array<double, 3> command_mm{};
  if (!get("abs_cmd_pos", deadline_ns, reply)) {
    return false;
  }
  if (!parse_xyz(reply, "ABS_CMD_POS", command_mm)) {
    static_cast<void>(fail(MachineFault::GarbledReply, "linuxcncrsh's answer to \"get abs_cmd_pos\" did not parse", reply));
    return false;
  }
  // LinuxCNC prints 6 decimals: a target on the step grid comes back within half a micrometre.
  bool short_of_it = false;
  for (std::size_t i = 0; i < 3; ++i) {
    short_of_it = short_of_it || std::fabs(command_mm[i] - mm_of(commanded_[i])) > 0.002;
  }
  // IDLE and its command short of the target: stopped on the way (its external e-stop aborts the
  // motion a moment before its status says ESTOP ON). Seen twice in a row, since IDLE can also
  // come a moment before a new move starts (once in a hundred, measured).
  if (short_of_it && ++at_rest_short_ >= 2) {
    std::array<char, 220> what{};
    std::snprintf(what.data(), what.size(), "LinuxCNC stopped with its command at %.4f %.4f %.4f mm, short of %.4f %.4f %.4f mm",
                  command_mm[0], command_mm[1], command_mm[2], mm_of(commanded_[0]), mm_of(commanded_[1]),
                  mm_of(commanded_[2]));
    static_cast<void>(fail(MachineFault::PositionMismatch, what.data()));
    return false;
  }
  if (short_of_it) {
    return true;
  }
  at_rest_short_ = 0;
  if (!actual_too) {
    return true;
  }
  if (!read_position(deadline_ns)) {
    return false;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (std::fabs(actual_mm_[i] - mm_of(commanded_[i])) > config_.position_tolerance_mm) {
      std::array<char, 220> what{};
      std::snprintf(what.data(), what.size(), "LinuxCNC stands at %.4f %.4f %.4f mm, commanded %.4f %.4f %.4f mm",
                    actual_mm_[0], actual_mm_[1], actual_mm_[2], mm_of(commanded_[0]), mm_of(commanded_[1]),
                    mm_of(commanded_[2]));
      static_cast<void>(fail(MachineFault::PositionMismatch, what.data()));
      return false;
    }
  }
  return true;
}

MachineResult LinuxcncLink::set_spindle(bool on, MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (!machine_on_ || state_ == MachineState::Closed || state_ == MachineState::Open) {
    return refuse(MachineRefusal::NotHomed);
  }
  if (!set(on ? "set spindle forward" : "set spindle off", "SPINDLE", deadline_ns) || !check_health(deadline_ns)) {
    return {false, MachineRefusal::None, fault_};
  }
  spindle_on_ = on;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineResult LinuxcncLink::keep_alive(MonotonicNs deadline_ns) {
  if (fault_ != MachineFault::None) {
    return refuse(MachineRefusal::Faulted);
  }
  if (!machine_on_) {
    return {true, MachineRefusal::None, MachineFault::None};  // stopped: nothing to watch but the next start
  }
  // At rest it must stand where it was told. LinuxCNC's external e-stop (its HAL chain) aborts the
  // motion while linuxcncrsh still answers ESTOP OFF and MACHINE ON (LinuxCNC 2.9, measured with
  // sim/linuxcnc_mill): a mill that stopped short is how it shows.
  if (!check_health(deadline_ns) || (homed_ && (!update_moves_done(deadline_ns) || !compare_at_rest(deadline_ns, false)))) {
    return {false, MachineRefusal::None, fault_};
  }
  return {true, MachineRefusal::None, MachineFault::None};
}

void LinuxcncLink::hold() {
  // Every move lasts at most an update, so holding takes effect at the next: moves are refused.
  if (state_ != MachineState::Held && state_ != MachineState::Fault) {
    before_hold_ = state_;
    state_ = MachineState::Held;
  }
}

void LinuxcncLink::resume() {
  if (state_ == MachineState::Held) {
    state_ = before_hold_;
  }
}

MachineResult LinuxcncLink::stop(MonotonicNs deadline_ns) {
  homed_ = false;
  spindle_on_ = false;
  if (!channel_.is_open()) {
    machine_on_ = false;
    if (fault_ == MachineFault::None) {
      state_ = MachineState::Stopped;
    }
    return {fault_ == MachineFault::None, MachineRefusal::None, fault_};
  }
  // Past a fault too: whatever LinuxCNC still takes is turned off. A fault latched here keeps the first one's words.
  const MachineFault before = fault_;
  const std::array<char, 320> reason = last_error_;
  fault_ = MachineFault::None;
  std::string_view reply;
  const bool off = set("set abort", "ABORT", deadline_ns) && set("set machine off", "MACHINE", deadline_ns) &&
                   await_value("machine", "MACHINE", "OFF", deadline_ns, reply) && value_of(reply, "MACHINE") == "OFF";
  const MachineFault during = fault_;
  if (before != MachineFault::None) {
    fault_ = before;
    last_error_ = reason;
  } else {
    fault_ = during;
  }
  machine_on_ = !off;
  if (fault_ != MachineFault::None) {
    state_ = MachineState::Fault;
    return {false, MachineRefusal::None, fault_};
  }
  if (!off) {
    return fail(MachineFault::ControllerError, "LinuxCNC's machine did not turn off", reply);
  }
  state_ = MachineState::Stopped;
  return {true, MachineRefusal::None, MachineFault::None};
}

MachineStatus LinuxcncLink::status() const {
  return {state_,       fault_,       commanded_, homed_, spindle_on_, machine_on_, moves_done_, channel_.bytes_sent(),
          channel_.bytes_received()};
}

}  // namespace stencil::hal::linuxcnc
