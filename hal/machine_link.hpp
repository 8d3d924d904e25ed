// MachineLink: the mill as the machine thread sees it (targets in motor steps out, progress and
// faults back), with the plain-data target, status and fault types it exchanges.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "hal/clock.hpp"

namespace stencil::hal {

// One machine update: where the motors go (absolute motor steps from home, backlash compensation
// included) and the order in which the axes move (the mill steps one axis at a time, and the
// planner checked exactly this staircase).
struct MachineTarget {
  std::array<std::int32_t, 3> motor_steps;  // x y z
  std::array<std::uint8_t, 3> order;        // a permutation of 0 1 2
  bool cutting;                             // the tool may touch stock: refused while the spindle is off
};

enum class MachineState : std::uint8_t {
  Closed,    // no port
  Open,      // port open, controller not yet answering
  Ready,     // controller initialised; moves need homing first
  Homed,     // positions known: moves accepted
  Held,      // feed hold: moves refused until resume()
  Stopped,   // stopped, drivers off: moves refused until homed again
  Fault,     // latched: see MachineFault; the machine is considered stopped
};

enum class MachineFault : std::uint8_t {
  None,
  NotATty,           // the port path is not a serial device
  OpenFailed,        // open or termios set-up failed
  NoAnswer,          // start-up: the controller never answered a query
  Timeout,           // a reply did not come within its bound
  GarbledReply,      // a reply that is not what the command gives
  PortClosed,        // the port hung up (unplugged)
  WriteFailed,       // the port would not take the bytes within the bound
  PositionMismatch,  // the controller's position differs from the commanded one
  EstopPressed,      // the controller's own e-stop (LinuxCNC: ESTOP ON)
  ControllerError,   // the controller reported an error or turned its machine off (its words: the link's last error)
  CommandRefused,    // the controller refused a command (linuxcncrsh: SET ... NAK, HELLO NAK)
};

// Why a call did nothing (besides a fault).
enum class MachineRefusal : std::uint8_t {
  None,
  NotHomed,     // no move before homing (or after a stop)
  Held,         // feed hold is on
  SpindleOff,   // a cutting move while the spindle is off: the interlock
  TooLong,      // the move would last longer than one machine update
  BadTarget,    // order not a permutation, or steps out of the controller's range
  Faulted,      // the fault latch is set
  DeadlineTooShort,  // the caller's time bound cannot cover the work
  Aborted,      // the operator asked to stop (abort_on's flag) before the work was done
};

struct [[nodiscard]] MachineResult {
  bool done;
  MachineRefusal refusal;  // None when done or faulted
  MachineFault fault;      // None unless this call latched a fault
};

struct MachineStatus {
  MachineState state;
  MachineFault fault;                            // the latch
  std::array<std::int32_t, 3> commanded_steps;   // motor steps the controller was told to reach
  bool homed;
  bool spindle_on;
  bool drivers_on;
  std::uint64_t moves_done;
  std::uint64_t bytes_sent;
  std::uint64_t bytes_received;
};

// Every method returns by the absolute deadline it is given (MonotonicNs, the Clock's time) or
// sooner, whatever the controller does: a controller that does not answer in time is a fault, not a
// hang. Called by the machine thread at the update rate (about 30 Hz), never by the 1 kHz cycle:
// they may block on the port up to their deadline, but allocate nothing after opening.
class MachineLink {
 public:
  MachineLink() = default;
  MachineLink(const MachineLink&) = delete;
  MachineLink& operator=(const MachineLink&) = delete;

  // Wakes the controller (its adaptive baud rate) and initialises rates, slope and mode.
  virtual MachineResult start(MonotonicNs deadline_ns) = 0;
  // Seeks the home switch of every axis, then verifies the position by query. Motor steps count
  // from there; the slack of every axis is on the side homing approached from (reported by
  // home_approach()). The deadline should allow homing_bound_ns().
  // Set before start(): start() and home() look at *flag between commands and give up (refusal
  // Aborted, outputs off) once it is true: a stop asked for while homing is taken within one step;
  // one asked while starting once start() has turned off what an earlier run left latched on (the
  // wake-up and start-up are bounded by start()'s deadline).
  virtual void abort_on(const std::atomic<bool>* flag) = 0;
  // The longest homing can take from anywhere in the travel (ns): the caller's deadline for it.
  [[nodiscard]] virtual MonotonicNs homing_bound_ns() const = 0;
  virtual MachineResult home(MonotonicNs deadline_ns) = 0;
  // Manual homing for a rig without switches: the operator jogged the tool to the mark; this
  // position becomes motor step 0 of every axis.
  virtual MachineResult declare_home(MonotonicNs deadline_ns) = 0;
  // One update's move: each axis in target.order to its motor step count. Refused (nothing sent)
  // unless homed, not held, the spindle on for a cutting move, and short enough for one update.
  virtual MachineResult move(const MachineTarget& target, MonotonicNs deadline_ns) = 0;
  // Asks the controller where it is and compares with what it was told: a difference is a fault.
  virtual MachineResult verify(MonotonicNs deadline_ns) = 0;
  virtual MachineResult set_spindle(bool on, MonotonicNs deadline_ns) = 0;
  // The heartbeat the rig's hardware watchdog watches (a relay that cuts the spindle's and the
  // drivers' power when it stops): toggled when due, nothing sent otherwise. Call it at every update,
  // so that a process that dies, hangs or is killed leaves the mill without power within the relay's
  // time.
  virtual MachineResult keep_alive(MonotonicNs deadline_ns) = 0;
  // Feed hold: every move lasts at most one update, so holding takes effect at the next update.
  virtual void hold() = 0;
  virtual void resume() = 0;
  // Hold, spindle off and drivers off (the axes go limp): moves are refused until homed again.
  virtual MachineResult stop(MonotonicNs deadline_ns) = 0;

  [[nodiscard]] virtual MachineStatus status() const = 0;
  // +1 or -1 per axis: the direction of the last motion of homing (where the backlash slack is).
  [[nodiscard]] virtual std::array<int, 3> home_approach() const = 0;

 protected:
  ~MachineLink() = default;
};

}  // namespace stencil::hal
