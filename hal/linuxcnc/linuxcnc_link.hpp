// LinuxcncLink: a LinuxCNC mill as a MachineLink, over linuxcncrsh's text protocol (TCP). LinuxCNC
// owns the motion (its trajectory planner, limits, backlash compensation), the hardware e-stop and
// the spindle; this link hands it one straight G1 per machine update in exact-path mode (G61) and
// watches what it says. Why linuxcncrsh and not NML or HAL pins: README ("A LinuxCNC mill").
//
// What a machine update costs: linuxcncrsh answers a set once LinuxCNC's task has received it, and
// it polls for that every 0.1 s, so each move is about 100 ms on the wire (gets about 0.2 ms). The
// rig's update rate for LinuxCNC is therefore about 8 Hz, against the CY545's 30.
//
// LinuxCNC's own words travel into last_error(): its e-stop, a following error ("joint 0 following
// error"), a refused MDI line ("Linear move on line 0 would exceed X's positive limit"), the machine
// turned off, or the connection lost each latch a fault, and the machine side stops.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string_view>

#include "hal/clock.hpp"
#include "hal/linuxcnc/tcp_line_channel.hpp"
#include "hal/machine_link.hpp"

namespace stencil::hal::linuxcnc {

// linuxcncrsh's passwords when none are given (linuxcncrsh(1)): refused by the link, since
// linuxcncrsh listens on every interface.
inline constexpr std::string_view kDefaultConnectPassword = "EMC";
inline constexpr std::string_view kDefaultEnablePassword = "EMCTOO";
inline constexpr std::size_t kMaxPasswordLength = 15;  // linuxcncrsh's buffers

struct LinuxcncConfig {
  std::array<char, 16> address{};         // IPv4 digits, NUL-terminated ("127.0.0.1")
  std::uint16_t port = 5007;
  std::array<char, 32> connect_password{};  // NUL-terminated; linuxcncrsh --connectpw
  std::array<char, 32> enable_password{};   // linuxcncrsh --enablepw
  double steps_per_mm = 640.0;            // motor step n of an axis is LinuxCNC's machine n / steps_per_mm mm
  std::array<double, 3> travel_mm{};      // machine mm per axis from home: targets outside are refused
  double max_move_mm = 0.0;               // the longest move an update may hold, per axis (the planner's budget)
  double feed_mm_per_min = 300.0;         // F of every G1 (LinuxCNC keeps each axis within its INI limits)
  double position_tolerance_mm = 0.02;    // verify: LinuxCNC's actual position at rest against the commanded
                                          // (its motor settles a few ms after its command, up to 17 um behind)
  MonotonicNs reply_timeout_ns = 400'000'000;   // a set's answer (about 100 ms when well)
  MonotonicNs homing_bound_ns = 60'000'000'000;  // LinuxCNC's homing sequence from anywhere
  MonotonicNs homing_poll_ns = 50'000'000;      // JOINT_HOMED asked this often while homing
  MonotonicNs status_settle_ns = 500'000'000;   // how long a set's effect may take to show in LinuxCNC's status
};

// Empty when the configuration can be used; else what is wrong with it (default passwords, an
// address that is not IPv4 digits, a password with a space, travel or steps not positive).
[[nodiscard]] std::string_view check_linuxcnc_config(const LinuxcncConfig& config);

class LinuxcncLink final : public MachineLink {
 public:
  LinuxcncLink(Clock& clock, const LinuxcncConfig& config);

  MachineResult start(MonotonicNs deadline_ns) override;
  void abort_on(const std::atomic<bool>* flag) override { abort_ = flag; }
  [[nodiscard]] MonotonicNs homing_bound_ns() const override { return config_.homing_bound_ns; }
  MachineResult home(MonotonicNs deadline_ns) override;
  // LinuxCNC homes as its INI says: a mill without switches has HOME_SEARCH_VEL = 0, which takes the
  // place it stands as home. So the same as home().
  MachineResult declare_home(MonotonicNs deadline_ns) override { return home(deadline_ns); }
  MachineResult move(const MachineTarget& target, MonotonicNs deadline_ns) override;
  MachineResult verify(MonotonicNs deadline_ns) override;
  MachineResult set_spindle(bool on, MonotonicNs deadline_ns) override;
  // LinuxCNC has its own watchdogs (its e-stop chain); here the update's look at it: e-stop, machine
  // on, an error, the moves done.
  MachineResult keep_alive(MonotonicNs deadline_ns) override;
  void hold() override;
  void resume() override;
  // Abort (LinuxCNC stops the motion and flushes the queue), then machine off (drives disabled,
  // spindle off), confirmed by "MACHINE OFF".
  MachineResult stop(MonotonicNs deadline_ns) override;
  [[nodiscard]] MachineStatus status() const override;
  // LinuxCNC takes up its own backlash: no side of the slack matters here.
  [[nodiscard]] std::array<int, 3> home_approach() const override { return {1, 1, 1}; }

  [[nodiscard]] const char* last_error() const { return last_error_.data(); }
  // LinuxCNC's actual position at the last look (machine mm).
  [[nodiscard]] const std::array<double, 3>& actual_mm() const { return actual_mm_; }

 private:
  MachineResult fail(MachineFault fault, std::string_view what, std::string_view words = {});
  void note_error(std::string_view what, std::string_view words);
  [[nodiscard]] MachineResult refuse(MachineRefusal refusal) const;
  // Sends a line; reads the answer into reply_. False (fault latched) on a timeout or a lost link.
  bool exchange(std::string_view line, MonotonicNs deadline_ns, std::string_view& reply);
  // A set with its ACK (verbose is on): a NAK or anything else is a fault naming the command.
  bool set(std::string_view command, std::string_view name, MonotonicNs deadline_ns);
  // A get: the answer line.
  bool get(std::string_view what, MonotonicNs deadline_ns, std::string_view& reply);
  // Asks `what` until its value is `expected` (LinuxCNC's status lags a set's ACK), at most
  // status_settle_ns: the last answer in `reply`.
  bool await_value(std::string_view what, std::string_view key, std::string_view expected, MonotonicNs deadline_ns,
                   std::string_view& reply);
  // Asks for LinuxCNC's errors until "ERROR OK" (a few at most): the first is latched as a fault
  // (ControllerError) unless `drop` (start-up, where an earlier run's errors are stale).
  bool check_errors(MonotonicNs deadline_ns, bool drop);
  // E-stop, machine on, errors: every look at LinuxCNC.
  bool check_health(MonotonicNs deadline_ns);
  bool read_position(MonotonicNs deadline_ns);
  bool update_moves_done(MonotonicNs deadline_ns);
  // After "G53 G0" to home: waits (polling, bounded by the deadline) until LinuxCNC stands there.
  bool await_home(MonotonicNs deadline_ns);
  // Once every move is done: LinuxCNC's command must be the last target (else it stopped short), and
  // with `actual_too` its actual position within position_tolerance_mm of it.
  bool compare_at_rest(MonotonicNs deadline_ns, bool actual_too);
  [[nodiscard]] bool abort_asked() const { return abort_ != nullptr && abort_->load(std::memory_order_relaxed); }
  [[nodiscard]] double mm_of(std::int32_t steps) const { return static_cast<double>(steps) / config_.steps_per_mm; }

  Clock& clock_;
  LinuxcncConfig config_;
  TcpLineChannel channel_;
  MachineState state_ = MachineState::Closed;
  MachineState before_hold_ = MachineState::Closed;
  MachineFault fault_ = MachineFault::None;
  std::array<std::int32_t, 3> commanded_{};
  std::array<double, 3> actual_mm_{};
  bool homed_ = false;
  bool spindle_on_ = false;
  bool machine_on_ = false;
  const std::atomic<bool>* abort_ = nullptr;
  std::uint64_t moves_sent_ = 0;
  int at_rest_short_ = 0;  // looks in a row that found LinuxCNC idle short of its target
  std::uint64_t moves_done_ = 0;
  std::array<char, 96> command_{};    // the line being built
  std::array<char, 320> last_error_{};
};

}  // namespace stencil::hal::linuxcnc
