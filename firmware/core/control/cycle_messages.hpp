// The plain-data records the cycle exchanges with the threads around it, each through its own
// SpscRing: commands in, and out the machine handoff, telemetry and the journal.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/control/spsc_ring.hpp"
#include "firmware/core/stencil/haptic_force.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "hal/haptic_device.hpp"
#include "hal/machine_link.hpp"

namespace stencil::control {

enum class CommandKind : std::uint8_t {
  Reset,  // leave the safe state (accepted only while the device is held still near the virtual tool)
  Stop,   // enter it (SIGINT/SIGTERM, the terminal, the display)
  JournalFailed,  // enter it: the journal writer could not write the record (the cut must stop)
  // The operator's parameters (the display), taken at the cycle's boundary; `value` in the unit named.
  // The cycle clamps each to the board's own limit whatever it is sent (see ParameterOutcome).
  SetCoupling,    // N per device mm: the pull of the device towards the virtual tool
  SetForceLimit,  // N: never above the board's limit (ControllerConfig::haptic at start-up)
  SetSpeedLimit,  // world mm/s of the virtual tool: never above the mill's (the config's move limits)
  // Feed hold: the virtual tool stops following the hand (which feels it held in place) and the mill
  // holds where it is; Resume carries on from there, without a reset or homing.
  Pause,
  Resume,
  // The wall's feel (issue 29; engine::WallFeel), operator's parameters like the three above. Last,
  // so that the kinds journalled before them keep their numbers.
  SetDamping,        // N s per device metre of virtual damping in the wall, 0 (none) to the config's most;
                     // the passivity controller runs while it is above 0
  SetFriction,       // the Coulomb friction coefficient of the virtual tool on the part, 0 to 1
  SetSpeedLimiting,  // 0: the cap on the virtual tool's speed alone; 1: with the penalty on the hand too
};

// Where a command (and so a safe state) came from, for the journal, the report and the display.
enum class CommandSource : std::uint8_t {
  Cycle,     // no command: the cycle's own checks (the device, the engine, the loop's timing)
  Machine,   // the machine side (its link's fault, a target it could not record)
  Program,   // the controller program itself: the job's time is up, the journal failed
  Signal,    // SIGINT/SIGTERM
  Terminal,  // the rig's operator terminal
  Display,   // an operator display
  Replay,    // a replay of a journal, the safe state its record shows without a command
  Control,   // a control command over the controller's socket (stencil-rig stop, reset, ...)
};

[[nodiscard]] constexpr const char* command_source_name(CommandSource source) {
  switch (source) {
    case CommandSource::Cycle:
      return "cycle";
    case CommandSource::Machine:
      return "machine";
    case CommandSource::Program:
      return "program";
    case CommandSource::Signal:
      return "signal";
    case CommandSource::Terminal:
      return "terminal";
    case CommandSource::Display:
      return "display";
    case CommandSource::Replay:
      return "replay";
    case CommandSource::Control:
      return "control";
  }
  return "unknown";
}
inline constexpr std::uint8_t kCommandSourceCount = 8;

struct Command {
  CommandKind kind;
  double value = 0.0;  // the Set* commands' new value
  CommandSource source = CommandSource::Program;
  // Stamped by CommandRing::push: how many cycles had begun when it was queued (the cycle that takes
  // it records both, so the record shows how long it waited).
  std::uint64_t queued_after_cycle = 0;
};

[[nodiscard]] constexpr const char* command_kind_name(CommandKind kind) {
  switch (kind) {
    case CommandKind::Reset:
      return "reset";
    case CommandKind::Stop:
      return "stop";
    case CommandKind::JournalFailed:
      return "journal_failed";
    case CommandKind::SetCoupling:
      return "set_coupling";
    case CommandKind::SetForceLimit:
      return "set_force_limit";
    case CommandKind::SetSpeedLimit:
      return "set_speed_limit";
    case CommandKind::Pause:
      return "pause";
    case CommandKind::Resume:
      return "resume";
    case CommandKind::SetDamping:
      return "set_damping";
    case CommandKind::SetFriction:
      return "set_friction";
    case CommandKind::SetSpeedLimiting:
      return "set_speed_limiting";
  }
  return "unknown";
}
inline constexpr std::uint8_t kCommandKindCount = 11;

// Whether the command sets one of the operator's parameters.
[[nodiscard]] constexpr bool is_parameter(CommandKind kind) {
  return kind == CommandKind::SetCoupling || kind == CommandKind::SetForceLimit || kind == CommandKind::SetSpeedLimit ||
         kind == CommandKind::SetDamping || kind == CommandKind::SetFriction || kind == CommandKind::SetSpeedLimiting;
}

// Whether 0 is one of the parameter's values (no damping, no friction, the cap alone) rather than
// a refusal.
[[nodiscard]] constexpr bool zero_allowed(CommandKind kind) {
  return kind == CommandKind::SetDamping || kind == CommandKind::SetFriction || kind == CommandKind::SetSpeedLimiting;
}

// The operator's parameter a Set* command sets, by the name the display uses in its requests and
// its state feed ("coupling", "force_limit", "speed_limit", "damping", "friction", "speed_limiting");
// "none" for the other commands.
[[nodiscard]] constexpr const char* parameter_name(CommandKind kind) {
  switch (kind) {
    case CommandKind::SetCoupling:
      return "coupling";
    case CommandKind::SetForceLimit:
      return "force_limit";
    case CommandKind::SetSpeedLimit:
      return "speed_limit";
    case CommandKind::SetDamping:
      return "damping";
    case CommandKind::SetFriction:
      return "friction";
    case CommandKind::SetSpeedLimiting:
      return "speed_limiting";
    case CommandKind::Reset:
    case CommandKind::Stop:
    case CommandKind::JournalFailed:
    case CommandKind::Pause:
    case CommandKind::Resume:
      break;
  }
  return "none";
}

// What the cycle made of the newest Set* command.
enum class ParameterOutcome : std::uint8_t {
  None,     // none taken yet
  Applied,  // as asked
  Clamped,  // above the board's limit (or below the least): the limit applies instead
  Refused,  // not a finite positive number (damping, friction: not finite or below 0; speed limiting:
            // neither 0 nor 1): nothing changed
};

[[nodiscard]] constexpr const char* parameter_outcome_name(ParameterOutcome outcome) {
  switch (outcome) {
    case ParameterOutcome::None:
      return "none";
    case ParameterOutcome::Applied:
      return "applied";
    case ParameterOutcome::Clamped:
      return "clamped";
    case ParameterOutcome::Refused:
      return "refused";
  }
  return "unknown";
}

// Why a reset was refused, or that it was taken.
enum class ResetOutcome : std::uint8_t {
  Accepted,
  NotInSafeState,
  DeviceNotStill,     // the device moved faster than the still speed in the still time
  DeviceFarFromTool,  // the device is not near the virtual tool: force would jump
  DeviceNotReady,     // no fresh sample, or the haptic link still latches a fault
};

// What a reset came to, for the operator ("accepted", "device_not_still", ...).
[[nodiscard]] constexpr const char* reset_outcome_name(ResetOutcome outcome) {
  switch (outcome) {
    case ResetOutcome::Accepted:
      return "accepted";
    case ResetOutcome::NotInSafeState:
      return "not_in_safe_state";
    case ResetOutcome::DeviceNotStill:
      return "device_not_still";
    case ResetOutcome::DeviceFarFromTool:
      return "device_far_from_tool";
    case ResetOutcome::DeviceNotReady:
      return "device_not_ready";
  }
  return "unknown";
}

// What the cycle made of a command it took, whatever its kind: the journal's and the report's word.
enum class CommandOutcome : std::uint8_t {
  Done,               // Stop: the safe state entered; Pause, Resume: done; Reset: accepted; Set*: applied as asked
  Clamped,            // Set*: the board's limit (or the least) applies instead
  Refused,            // Set*: not a number the parameter can take, nothing changed
  AlreadySafe,        // Stop, JournalFailed: the safe state was latched already (its first reason stays)
  NotInSafeState,     // Reset: nothing to reset
  DeviceNotStill,     // Reset: see ResetOutcome
  DeviceFarFromTool,
  DeviceNotReady,
  NotRunning,         // Pause: the cycle is in its safe state or waits for the hand
  AlreadyPaused,
  NotPaused,          // Resume
  RunEnding,          // Reset after the run's own stop (a signal, the job's end): the run ends, nothing resets it
  NoRecordRoom,       // the ring of taken commands was full: not taken (the cycle enters JournalFull)
};
inline constexpr std::uint8_t kCommandOutcomeCount = 13;

[[nodiscard]] constexpr const char* command_outcome_name(CommandOutcome outcome) {
  switch (outcome) {
    case CommandOutcome::Done:
      return "done";
    case CommandOutcome::Clamped:
      return "clamped";
    case CommandOutcome::Refused:
      return "refused";
    case CommandOutcome::AlreadySafe:
      return "already_safe";
    case CommandOutcome::NotInSafeState:
      return "not_in_safe_state";
    case CommandOutcome::DeviceNotStill:
      return "device_not_still";
    case CommandOutcome::DeviceFarFromTool:
      return "device_far_from_tool";
    case CommandOutcome::DeviceNotReady:
      return "device_not_ready";
    case CommandOutcome::NotRunning:
      return "not_running";
    case CommandOutcome::AlreadyPaused:
      return "already_paused";
    case CommandOutcome::NotPaused:
      return "not_paused";
    case CommandOutcome::RunEnding:
      return "run_ending";
    case CommandOutcome::NoRecordRoom:
      return "no_record_room";
  }
  return "unknown";
}

// One command the cycle took, for the journal (a record of its own: a replay gives the cycle the
// same commands at the same cycles), the report and the display's event list.
struct CommandEvent {
  std::uint64_t cycle;               // the cycle that took it
  std::int64_t time_ns;              // that cycle's start
  std::uint64_t queued_after_cycle;  // cycles begun when it was queued: cycle - this is its wait
  CommandKind kind;
  CommandSource source;
  CommandOutcome outcome;
  double asked;    // Set*: the value asked (its unit); else 0
  double applied;  // Set*: the value in force after it (the same unit; unlimited speed: infinity)
};

// Every cycle, to the machine side: where the virtual tool is (world mm, always legal) and whether
// the machine must stop.
struct MachineHandoff {
  std::uint64_t cycle;
  double virtual_tip_mm[3];
  bool safe_state;  // hold the feed, then switch the drivers off; move nothing until reset
  bool paused;      // feed hold: the mill holds where it is and takes no target until this clears
};

// From the machine side, when something happens there.
enum class MachineEventKind : std::uint8_t {
  Fault,    // the link latched a fault: the cycle enters the safe state
  Stopped,  // the machine is stopped (after a safe state): for the record
  JournalFailed,  // a target could not be recorded, so it was not sent: the cycle enters the safe state
  Backlog,        // how much of the path the mill has still to follow (each update): the cycle slows the tool
};

struct MachineEvent {
  MachineEventKind kind;
  hal::MachineFault fault = hal::MachineFault::None;  // Fault, JournalFailed: what the link had latched
  bool stop_confirmed = false;                         // Stopped: the link confirmed spindle and drivers off
  std::uint8_t backlog_percent = 0;                    // Backlog: how full the planner's path is, % of its capacity
};

// About 20 Hz is enough for people; the cycle pushes every cycle and a full ring drops (counted).
struct Telemetry {
  std::uint64_t cycle;
  std::int64_t time_ns;
  double device_mm[3];       // device space
  double desired_tip_mm[3];  // world
  double virtual_tip_mm[3];  // world
  double force_n[3];         // as written to the device
  double max_depth_mm;       // deepest penetration at the desired pose
  std::uint32_t touched_triangles;
  engine::RemediationStatus remediation;
  SafeReason safe_reason;
  std::uint32_t reset_requests;  // reset commands taken so far (accepted or refused)
  ResetOutcome last_reset;       // what the newest of them came to
  // For a reset control: how long the device has been held still, and how far it is from the
  // virtual tool (device mm); the cycle's own reset rule decides, these let a display say why not.
  double device_still_s;
  double device_to_tool_mm;
  // The loop's health: this cycle's wake-up latency and the previous cycle's compute time.
  std::int64_t wakeup_ns;
  std::int64_t last_compute_ns;
  // The parameters in force, and what the newest Set* command came to.
  double coupling_n_per_device_mm;
  double force_limit_n;
  double speed_limit_mm_per_s;   // infinity: unlimited
  double damping_n_s_per_m;
  double friction;
  engine::SpeedLimiting speed_limiting;
  std::uint32_t parameter_requests;
  CommandKind last_parameter;
  ParameterOutcome last_parameter_outcome;
  bool paused;                  // the operator's feed hold
  CommandSource safe_source;    // where the safe state came from (Cycle when none)
};

// Everything a replay needs and nothing is allowed to lose: the journal ring being full is a fault.
struct JournalRecord {
  std::uint64_t cycle;
  std::int64_t time_ns;
  double device_mm[3];
  double angles_rad[2];
  std::uint32_t sample_counter;
  bool fresh;                // a new sample this cycle, accepted by the cycle
  double virtual_tip_mm[3];
  SafeReason safe_reason;    // as latched at the end of the cycle
  std::uint32_t touched_triangles;  // the touched set's size after the cycle: progress, and a check on a rebuild
  float force_n[3];          // as written to the device
  // The cycle's read as the device gave it (device_mm, angles_rad, sample_counter and status_bits are
  // its sample when read_status is Fresh, even if the cycle refused it; else the last sample used).
  std::uint16_t status_bits;
  hal::ReadStatus read_status;
  hal::HapticFault read_reason;
  // The run's largest force written and offset of the hand from the virtual tool so far (the cycle's
  // running maxima): a resumed job's report covers its earlier runs without their every cycle.
  double max_force_n;
  double max_offset_mm;
  // Not in the Cycle record's bytes: the writer puts them in the SafeState record it writes with the
  // first record in the safe state, and the paused flag shows in the Pause and Resume records.
  CommandSource safe_source;
  bool paused;
};

// The rings around the cycle: capacities in the types. The machine side drains its ring at each
// machine update (about 30 Hz), so it holds well over a machine update's worth of cycles.
using MachineHandoffRing = SpscRing<MachineHandoff, 512>;
using MachineEventRing = SpscRing<MachineEvent, 16>;
using TelemetryRing = SpscRing<Telemetry, 64>;
using JournalRing = SpscRing<JournalRecord, 4096>;
// The records thread drains it with the journal's ring, every 50 ms at most and later when the disk
// stalls (the journal ring lasts 4 s): 1024 holds far more than the displays (10 requests a second
// each, 8 of them) and the terminal can send meanwhile. Full, the command is not taken (nothing
// unrecorded is ever applied) and the cycle enters JournalFull.
using CommandEventRing = SpscRing<CommandEvent, 1024>;

// Commands into the cycle from one producer thread. It stamps each with the cycles the cycle had
// begun (the cycle tells it at each look), so the record shows how long a command waited.
class CommandRing {
 public:
  static constexpr std::size_t kCapacity = 16;
  [[nodiscard]] static constexpr std::size_t capacity() { return kCapacity; }
  // The producer. Real-time safe.
  [[nodiscard]] bool push(Command command) {
    command.queued_after_cycle = cycles_begun_.load(std::memory_order_relaxed);
    return ring_.push(command);
  }
  // The cycle: its count first, then what is queued.
  void begin_look(std::uint64_t cycle) { cycles_begun_.store(cycle, std::memory_order_relaxed); }
  [[nodiscard]] bool pop(Command& command) { return ring_.pop(command); }
  [[nodiscard]] std::size_t size() const { return ring_.size(); }

 private:
  SpscRing<Command, kCapacity> ring_;
  std::atomic<std::uint64_t> cycles_begun_{0};
};

struct CycleRings {
  CommandRing& commands;          // in: reset, stop, ... from the records thread (signals, terminal, program)
  MachineEventRing& machine_events;  // in: the machine side's faults
  MachineHandoffRing& machine;    // out: every cycle's virtual tool
  TelemetryRing& telemetry;       // out: dropped and counted when full
  JournalRing& journal;           // out: full is a fault
  CommandEventRing& command_events;  // out: each command taken; full is a fault (the record would lose it)
  // in: an operator display's requests, pushed by its own server thread (so a Stop is taken by the
  // next cycle, not at the records thread's next look); null when there is no display.
  CommandRing* display_commands = nullptr;
};

// The rings of one cycle, owned together: a board allocates one of these at start-up (they are
// large: the journal ring alone holds seconds of records) and hands the cycle its rings().
struct CycleRingStorage {
  CommandRing commands;
  MachineEventRing machine_events;
  MachineHandoffRing machine;
  TelemetryRing telemetry;
  JournalRing journal;
  CommandEventRing command_events;
  [[nodiscard]] CycleRings rings(CommandRing* display_commands = nullptr) {
    return {commands, machine_events, machine, telemetry, journal, command_events, display_commands};
  }
};

}  // namespace stencil::control
