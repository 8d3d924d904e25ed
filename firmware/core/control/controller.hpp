// Controller: the 1 kHz cycle. One step() per period: commands in, read the device sample and check
// it, the engine (map it to the world, query and remediate), write the force, publish (the journal
// record, the virtual tool to the machine side, telemetry); and the safe state, latched, with its
// reset rule.
#pragma once

#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/loop_statistics.hpp"
#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/stencil/contact_query.hpp"
#include "firmware/core/stencil/haptic_force.hpp"
#include "firmware/core/stencil/passivity_controller.hpp"
#include "firmware/core/stencil/triangle_set.hpp"
#include "firmware/core/stencil/velocity_filter.hpp"
#include "firmware/core/stencil/velocity_predictor.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "hal/haptic_device.hpp"

namespace stencil::control {

// What a board decides about the cycle (the rig's numbers by default).
struct ControllerConfig {
  motion::MachineFrames frames;           // device -> world
  engine::ContactParameters contact;
  engine::HapticLimits haptic;
  engine::WallFeel feel;                  // damping, passivity, friction: all off by default
  Eigen::Vector3d device_low_mm;          // a sample outside [low, high] (device mm) is out of the reach
  Eigen::Vector3d device_high_mm;
  Eigen::Vector3d home_tip_mm;            // world: where the virtual tool starts (the machine's home)
  double contact_tolerance_mm = 0.005;    // a point this near the virtual tool is touched
  // The virtual tool keeps this far clear of the part (engine/standoff.hpp): the mill can then always
  // follow it (motion/machine_planner.hpp has the argument); as much stock is left on the part.
  // 0: none (the engine's own tests); a board sets its own (above motion::follow_standoff_needed_mm).
  double standoff_mm = 0.0;
  // The most the virtual tool may move in one period, per axis and all axes together (|dx|+|dy|+|dz|),
  // so the mill can follow (motion::MachineSpeed times the period); unlimited by default.
  double max_axis_move_mm = std::numeric_limits<double>::infinity();
  double max_total_move_mm = std::numeric_limits<double>::infinity();
  int stale_periods = 5;                  // more periods than this without a fresh sample: safe state
  double max_device_speed_mm_per_s = 3000.0;  // faster than a hand can move the handle: a jump
  int overrun_limit = 3;                  // more consecutive overruns than this: safe state
  bool count_overruns = true;             // false on a virtual clock, where lateness means nothing
  double still_speed_mm_per_s = 2.0;      // a reset needs the device slower than this ...
  double still_time_s = 0.5;              // ... for this long ...
  double reset_distance_mm = 5.0;         // ... and this near the virtual tool (device mm)
  double ramp_time_s = 0.5;               // force comes back over this long after a reset
  // The rig: the cycle starts held (zero force, the virtual tool at home) until the hand is held as
  // for a reset (still, near the tool); the simulation's scripted hand starts at once.
  bool start_held = false;
  double period_s = 1e-3;                 // the cycle's period: a speed limit in mm/s is this much per step
  // The operator may set the coupling within [min, max] (N per device mm); the force limit and the
  // speed limit only ever below the board's (haptic.max_force_n and the move limits above).
  double min_coupling_n_per_device_mm = 0.05;
  double max_coupling_n_per_device_mm = 2.0;
  // The most virtual damping the operator may set (N s per device metre). The wall test's damping
  // at the stiffest coupling is 10 + 21 x 3 = 73, and nothing above that was measured; a damper on
  // the filtered velocity goes unstable near b T / m = 1 (velocity_predictor.hpp), 200 N s/m on the
  // device's 0.2 kg alone, so this keeps a margin of two even with no hand on the handle.
  double max_damping_n_s_per_m = 100.0;
};

// How near the real tool's surface a point of the part counts as touched: the tolerance beyond the
// standoff the virtual tool keeps (it never comes closer). The cycle and whoever re-marks the touched
// set from the virtual tool's tips (the display, a resumed job's rebuild) use this one figure.
[[nodiscard]] inline double touch_distance_mm(const ControllerConfig& config) {
  return config.contact_tolerance_mm + config.standoff_mm;
}

enum class CycleStatus : std::uint8_t {
  Running,    // force is being rendered
  SafeState,  // force zero, machine told to stop; see safe_reason()
};

// Counters of what the cycle refused or dropped, never reset.
struct CycleCounters {
  std::uint64_t fresh_samples = 0;
  std::uint64_t stale_reads = 0;
  std::uint64_t rejected_samples = 0;  // refused by the backend (range, torn, bad frames)
  std::uint64_t telemetry_dropped = 0;
  std::uint64_t safe_state_entries = 0;
  std::uint64_t resets_accepted = 0;
  std::uint64_t resets_refused = 0;
};

class Controller {
 public:
  // Init time: builds the grown tool for the touched set. `part`, `device` and the rings must outlive
  // the controller. The controller is large (the touched set): give it static storage.
  Controller(const tables::PartTables& part, hal::HapticDevice& device, const CycleRings& rings,
             const ControllerConfig& config);
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  // False when the grown contact tool or the standoff's grown tool could not be built (a bad tool in
  // the tables, a standoff out of range): do not run.
  [[nodiscard]] bool ready() const { return ready_; }
  // A held start still waiting for the hand (ControllerConfig::start_held).
  [[nodiscard]] bool waiting_for_hand() const { return waiting_for_hand_; }

  // One cycle, started at now_ns for the period that was due at deadline_ns. Real-time safe: no
  // allocation, lock, throw or blocking call; bounded work (the engine's bounds, the command ring's
  // capacity).
  [[nodiscard]] CycleStatus step(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns);

  // After step(): when it ended and when the next period is due, for the statistics and the
  // overrun watchdog (which may enter the safe state, writing zero force at once). Real-time safe.
  void finish(hal::MonotonicNs end_ns, hal::MonotonicNs next_deadline_ns);

  // Init time, before the first step(), never from the cycle: a resumed job's touched set, rebuilt
  // from the virtual tool's tips its journal recorded, in order (the cycle marks the same way).
  void recall_touched(const Eigen::Vector3d& tip_mm);

  // Whether lateness counts (ControllerConfig::count_overruns), switched by the cycle's own thread:
  // the simulation turns it on to inject a stalled host on its virtual clock.
  void set_count_overruns(bool on) { config_.count_overruns = on; }

  [[nodiscard]] SafeReason safe_reason() const { return safe_reason_; }
  [[nodiscard]] CommandSource safe_source() const { return safe_source_; }
  // The operator's feed hold (CommandKind::Pause): the virtual tool held, the mill held.
  [[nodiscard]] bool paused() const { return paused_; }
  [[nodiscard]] ResetOutcome last_reset() const { return last_reset_; }
  [[nodiscard]] const LoopStatistics& statistics() const { return statistics_; }
  [[nodiscard]] const CycleCounters& counters() const { return counters_; }
  [[nodiscard]] const engine::TriangleSet& touched() const { return touched_; }
  [[nodiscard]] Eigen::Vector3d virtual_tip_mm() const { return tool_.tip_mm(); }
  [[nodiscard]] const hal::HapticCommand& last_command() const { return last_command_; }
  [[nodiscard]] double max_force_n() const { return max_force_n_; }
  [[nodiscard]] double max_offset_mm() const { return max_offset_mm_; }  // device vs virtual tool, world

 private:
  void enter_safe_state(SafeReason reason, CommandSource source = CommandSource::Cycle);
  void write_zero_force();
  // Both command rings (the records thread's, then the display's), each command recorded as an event.
  void handle_commands(hal::MonotonicNs now_ns);
  void take_commands(CommandRing& ring, hal::MonotonicNs now_ns);
  [[nodiscard]] CommandOutcome take_command(const Command& command, hal::MonotonicNs now_ns);
  // A parameter as it stands, in its command's unit (speed: mm/s, infinity when unlimited).
  [[nodiscard]] double parameter_value(CommandKind kind) const;
  [[nodiscard]] ResetOutcome try_reset(hal::MonotonicNs now_ns);
  // The reset rule's hand: still long enough, near enough the virtual tool (Accepted when both).
  [[nodiscard]] ResetOutcome hand_held_near_tool(hal::MonotonicNs now_ns) const;
  [[nodiscard]] ParameterOutcome set_parameter(CommandKind kind, double value);
  // What the engine made of this cycle's sample, for the force and the telemetry.
  struct EngineOutcome {
    Eigen::Vector3d device_mm;       // the sample in use, device space
    Eigen::Vector3d desired_tip_mm;  // it in the world: where the hand wants the tool
    engine::ContactResult contact;   // at the desired pose (none when the engine did not run)
    engine::HapticOutput output;     // unramped force and torque (zero when the engine did not run)
    engine::RemediationStatus remediation;
  };

  // step()'s parts, in its order. Each real-time safe, as step() is.
  // The cycle's count, its wake-up latency and the periods it missed.
  void begin_cycle(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns);
  // Reads the device and checks the sample; false when the cycle must not render force.
  [[nodiscard]] bool read_device(hal::MonotonicNs now_ns);
  // Ends a held start once the hand is held still near the tool.
  void release_held_start(hal::MonotonicNs now_ns, bool usable);
  // Contact, remediation and force at the sample, when the cycle renders force (else all zero).
  [[nodiscard]] EngineOutcome run_engine(bool usable);
  // The force to the device: ramped in, or zero in the safe state and a held start.
  void write_force(hal::MonotonicNs now_ns, bool usable, const engine::HapticOutput& output);
  // The journal record, the machine handoff and the telemetry, in that order.
  void publish(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns, const EngineOutcome& outcome);
  // Where the virtual tool goes this cycle and how: towards the hand, or as the friction cone lets it.
  [[nodiscard]] engine::RemediationResult move_tool(const Eigen::Vector3d& desired, const engine::ContactResult& contact);
  // The wall's damping this cycle (N): the coupling's virtual damper and the passivity controller's
  // correction; zero with both off (today's rendering: nothing is computed, unless the speed penalty
  // needs the handle's velocity estimate, which this moves).
  [[nodiscard]] Eigen::Vector3d wall_damping(const Eigen::Vector3d& device_mm, const Eigen::Vector3d& desired,
                                             const engine::ContactResult& contact);
  // Penalty-based speed limiting (config_.feel.speed_limiting): the force against the handle's
  // velocity as it nears the speed the mill can follow (engine/speed_penalty.hpp), from the estimate
  // wall_damping() has just moved, predicted past its lag by the forces this has rendered.
  [[nodiscard]] Eigen::Vector3d speed_penalty();
  // The estimates start again (after any cycle that rendered no force): no stale velocity, no old balance.
  void restart_wall_feel();
  // The estimates alone (a change of the feel's parameters): a resting tool stays held.
  void restart_feel_estimates();
  [[nodiscard]] JournalRecord build_journal_record(hal::MonotonicNs now_ns) const;
  [[nodiscard]] Telemetry build_telemetry(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns,
                                          const EngineOutcome& outcome) const;

  const tables::PartTables& part_;
  hal::HapticDevice& device_;
  CycleRings rings_;
  ControllerConfig config_;
  engine::StandoffPart standoff_{};  // the part as the engine sees it (before tool_, which keeps a reference)
  bool standoff_built_ = false;
  engine::VirtualTool tool_;
  geometry::ToolBsp contact_tool_{};
  engine::TriangleSet touched_;
  bool ready_ = false;

  std::uint64_t cycle_ = 0;
  SafeReason safe_reason_ = SafeReason::None;
  CommandSource safe_source_ = CommandSource::Cycle;
  bool paused_ = false;
  bool run_ending_ = false;  // the run's own stop was taken: no reset after it
  ResetOutcome last_reset_ = ResetOutcome::NotInSafeState;
  hal::HapticSample sample_{};             // the last accepted sample
  hal::ReadResult read_{hal::ReadStatus::Stale, hal::HapticFault::None};  // this cycle's read, for the journal
  hal::HapticSample read_sample_{};        // what it gave when Fresh, accepted here or not
  bool have_sample_ = false;
  bool fresh_ = false;                     // this cycle's read gave a new sample
  hal::MonotonicNs sample_time_ns_ = 0;    // when it was read
  int cycles_since_fresh_ = 0;
  hal::MonotonicNs still_since_ns_ = 0;    // the device has been slower than the still speed since
  hal::MonotonicNs ramp_start_ns_ = 0;     // force ramps in from here after a reset (or the start)
  bool ramping_ = true;
  bool waiting_for_hand_ = false;  // a held start (config.start_held) until the hand is held near the tool
  int consecutive_overruns_ = 0;
  double backlog_percent_ = 0.0;           // the mill's path still to follow, from its last update
  hal::MonotonicNs step_start_ns_ = 0;
  hal::MonotonicNs step_deadline_ns_ = 0;
  hal::MonotonicNs next_deadline_ns_ = 0;  // from the last finish(): when the next step was due
  hal::MonotonicNs last_compute_ns_ = 0;   // the last finish()'s step time
  // The board's limits, from the config at start-up: what the operator's parameters never exceed.
  double board_force_limit_n_ = 0.0;
  double board_axis_move_mm_ = 0.0;
  double board_total_move_mm_ = 0.0;
  std::uint32_t parameter_requests_ = 0;
  CommandKind last_parameter_ = CommandKind::SetCoupling;
  ParameterOutcome last_parameter_outcome_ = ParameterOutcome::None;
  hal::HapticCommand last_command_{};
  double max_force_n_ = 0.0;
  double max_offset_mm_ = 0.0;
  // The wall's feel (config_.feel): the rate the coupling stretches, the handle's velocity (both
  // device metres per second), the energy balance, and the handle's last position.
  engine::VelocityFilter stretch_rate_;
  engine::VelocityFilter handle_velocity_;
  engine::VelocityPredictor speed_predictor_;  // the handle's velocity past the filter's lag, for the penalty
  engine::PassivityController passivity_;
  Eigen::Vector3d last_handle_m_ = Eigen::Vector3d::Zero();
  hal::MonotonicNs last_handle_ns_ = 0;  // when that sample was read
  bool have_last_handle_ = false;
  Eigen::Vector3d force_before_ = Eigen::Vector3d::Zero();  // the command before last_command_ (N)
  bool was_penetrating_ = false;                            // last cycle's desired pose was in contact
  bool tool_on_surface_ = false;  // friction: the tool rests on the part (it slid onto it, or was held)
  LoopStatistics statistics_;
  CycleCounters counters_;
};

}  // namespace stencil::control
