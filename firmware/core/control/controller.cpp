// The cycle: commands -> read -> engine -> write -> publish, and the latched safe state.
#include "firmware/core/control/controller.hpp"

#include <algorithm>
#include <cmath>

#include "firmware/core/motion/machine_planner.hpp"
#include "firmware/core/stencil/speed_penalty.hpp"
#include "firmware/core/stencil/surface_friction.hpp"

namespace stencil::control {
namespace {

constexpr double kNsPerS = 1e9;

// The virtual tool stops once the mill's path is this full: the path then has room for a whole
// handoff ring more (4096 x 13 % > 512), all a machine update can take in before it reports again,
// so the path never fills while the cycle runs (a full path would leave a gap in it).
constexpr double kBacklogHoldPercent = 87.0;
// Friction holds a tool that rests on the part: the part within this much below it along the normal
// (world mm; twice the contact tolerance).
constexpr double kRestingProbeMm = 0.01;
static_assert((100.0 - kBacklogHoldPercent) / 100.0 * motion::MachinePlanner::kPathCapacity >
              MachineHandoffRing::capacity());

Eigen::Vector3d position_of(const hal::HapticSample& sample) {
  return {sample.position_mm[0], sample.position_mm[1], sample.position_mm[2]};
}

void copy3(const Eigen::Vector3d& from, double (&to)[3]) {
  to[0] = from.x();
  to[1] = from.y();
  to[2] = from.z();
}

}  // namespace

Controller::Controller(const tables::PartTables& part, hal::HapticDevice& device, const CycleRings& rings,
                       const ControllerConfig& config)
    : part_(part),
      device_(device),
      rings_(rings),
      config_(config),
      standoff_built_(engine::build_standoff_part(part, config.standoff_mm, standoff_)),
      tool_(standoff_, config.home_tip_mm) {
  // Touched: within the tolerance of the virtual tool, which keeps the standoff off the part.
  ready_ = standoff_built_ &&
           engine::build_contact_tool(part.tool.spec, touch_distance_mm(config_), contact_tool_);
  tool_.limit_speed(config.max_axis_move_mm, config.max_total_move_mm);
  last_command_ = {{0.0, 0.0, 0.0}, {0.0, 0.0}, 0, false};
  board_force_limit_n_ = config.haptic.max_force_n;
  board_axis_move_mm_ = config.max_axis_move_mm;
  board_total_move_mm_ = config.max_total_move_mm;
  waiting_for_hand_ = config.start_held;
  stretch_rate_.configure(config.feel.velocity_cutoff_hz, config.period_s);
  handle_velocity_.configure(config.feel.velocity_cutoff_hz, config.period_s);
  speed_predictor_.configure(handle_velocity_.alpha(), config.period_s, config.feel.transport_delay_s);
}

ParameterOutcome Controller::set_parameter(CommandKind kind, double value) {
  if (!std::isfinite(value) || value < 0.0 || (value == 0.0 && !zero_allowed(kind))) {
    return ParameterOutcome::Refused;
  }
  switch (kind) {
    case CommandKind::SetCoupling: {
      const double applied =
          std::clamp(value, config_.min_coupling_n_per_device_mm, config_.max_coupling_n_per_device_mm);
      config_.haptic.coupling_n_per_device_mm = applied;
      return applied == value ? ParameterOutcome::Applied : ParameterOutcome::Clamped;
    }
    case CommandKind::SetForceLimit: {
      // Whatever it is sent, never above the board's limit.
      config_.haptic.max_force_n = std::min(value, board_force_limit_n_);
      return value <= board_force_limit_n_ ? ParameterOutcome::Applied : ParameterOutcome::Clamped;
    }
    case CommandKind::SetSpeedLimit: {
      const double per_step_mm = value * config_.period_s;
      config_.max_axis_move_mm = std::min(per_step_mm, board_axis_move_mm_);
      config_.max_total_move_mm = std::min(per_step_mm, board_total_move_mm_);
      tool_.limit_speed(config_.max_axis_move_mm, config_.max_total_move_mm);
      return per_step_mm <= board_axis_move_mm_ && per_step_mm <= board_total_move_mm_ ? ParameterOutcome::Applied
                                                                                        : ParameterOutcome::Clamped;
    }
    case CommandKind::SetDamping: {
      const double applied = std::min(value, config_.max_damping_n_s_per_m);
      if (applied != config_.feel.damping_n_s_per_m) {
        config_.feel.damping_n_s_per_m = applied;
        // The passivity controller goes with the damping: on, it takes back what the damper's delay
        // and the sampling put in; off, today's rendering exactly.
        config_.feel.passivity = applied > 0.0;
        restart_feel_estimates();
      }
      return applied == value ? ParameterOutcome::Applied : ParameterOutcome::Clamped;
    }
    case CommandKind::SetFriction: {
      config_.feel.friction = std::min(value, 1.0);
      return value <= 1.0 ? ParameterOutcome::Applied : ParameterOutcome::Clamped;
    }
    case CommandKind::SetSpeedLimiting:
      if (value != 0.0 && value != 1.0) {
        return ParameterOutcome::Refused;
      }
      {
        const engine::SpeedLimiting mode = value == 0.0 ? engine::SpeedLimiting::Cap : engine::SpeedLimiting::Penalty;
        if (mode != config_.feel.speed_limiting) {
          config_.feel.speed_limiting = mode;
          restart_feel_estimates();
        }
      }
      return ParameterOutcome::Applied;
    default:
      return ParameterOutcome::Refused;
  }
}

void Controller::write_zero_force() {
  last_command_ = {{0.0, 0.0, 0.0}, {0.0, 0.0}, static_cast<std::uint32_t>(cycle_), false};
  static_cast<void>(device_.write_command(last_command_));
}

void Controller::enter_safe_state(SafeReason reason, CommandSource source) {
  if (safe_reason_ != SafeReason::None) {
    return;  // latched: the first reason stays
  }
  safe_reason_ = reason;
  safe_source_ = source;
  paused_ = false;  // the stop supersedes a feed hold: after a reset the tool follows again
  ++counters_.safe_state_entries;
  write_zero_force();  // at once, whatever else this cycle still does
}

ResetOutcome Controller::hand_held_near_tool(hal::MonotonicNs now_ns) const {
  if (static_cast<double>(now_ns - still_since_ns_) < config_.still_time_s * kNsPerS) {
    return ResetOutcome::DeviceNotStill;
  }
  const Eigen::Vector3d tool_on_device = motion::world_to_device(config_.frames, tool_.tip_mm());
  if ((position_of(sample_) - tool_on_device).norm() > config_.reset_distance_mm) {
    return ResetOutcome::DeviceFarFromTool;
  }
  return ResetOutcome::Accepted;
}

ResetOutcome Controller::try_reset(hal::MonotonicNs now_ns) {
  if (safe_reason_ == SafeReason::None) {
    return ResetOutcome::NotInSafeState;
  }
  // A link that latched a fault is cleared only once it is connected again.
  if (device_.latched_fault() != hal::HapticFault::None && device_.link_state() == hal::HapticLinkState::Connected) {
    device_.clear_fault();
  }
  if (!have_sample_ || cycles_since_fresh_ > config_.stale_periods ||
      device_.latched_fault() != hal::HapticFault::None) {
    return ResetOutcome::DeviceNotReady;
  }
  const ResetOutcome hand = hand_held_near_tool(now_ns);
  if (hand != ResetOutcome::Accepted) {
    return hand;
  }
  safe_reason_ = SafeReason::None;
  safe_source_ = CommandSource::Cycle;
  ramp_start_ns_ = now_ns;
  ramping_ = true;
  consecutive_overruns_ = 0;
  backlog_percent_ = 0.0;  // the machine side stopped with the safe state: its last backlog says nothing now
  return ResetOutcome::Accepted;
}

namespace {

CommandOutcome outcome_of(ResetOutcome reset) {
  switch (reset) {
    case ResetOutcome::Accepted:
      return CommandOutcome::Done;
    case ResetOutcome::NotInSafeState:
      return CommandOutcome::NotInSafeState;
    case ResetOutcome::DeviceNotStill:
      return CommandOutcome::DeviceNotStill;
    case ResetOutcome::DeviceFarFromTool:
      return CommandOutcome::DeviceFarFromTool;
    case ResetOutcome::DeviceNotReady:
      return CommandOutcome::DeviceNotReady;
  }
  return CommandOutcome::Refused;
}

CommandOutcome outcome_of(ParameterOutcome parameter) {
  switch (parameter) {
    case ParameterOutcome::Applied:
      return CommandOutcome::Done;
    case ParameterOutcome::Clamped:
      return CommandOutcome::Clamped;
    case ParameterOutcome::None:
    case ParameterOutcome::Refused:
      break;
  }
  return CommandOutcome::Refused;
}

}  // namespace

double Controller::parameter_value(CommandKind kind) const {
  switch (kind) {
    case CommandKind::SetCoupling:
      return config_.haptic.coupling_n_per_device_mm;
    case CommandKind::SetForceLimit:
      return config_.haptic.max_force_n;
    case CommandKind::SetSpeedLimit:
      return config_.max_axis_move_mm / config_.period_s;
    case CommandKind::SetDamping:
      return config_.feel.damping_n_s_per_m;
    case CommandKind::SetFriction:
      return config_.feel.friction;
    case CommandKind::SetSpeedLimiting:
      return config_.feel.speed_limiting == engine::SpeedLimiting::Penalty ? 1.0 : 0.0;
    default:
      return 0.0;
  }
}

CommandOutcome Controller::take_command(const Command& command, hal::MonotonicNs now_ns) {
  switch (command.kind) {
    case CommandKind::Stop:
    case CommandKind::JournalFailed: {
      const bool was_safe = safe_reason_ != SafeReason::None;
      // The run's own stop (a signal, the job's time up, the journal failing) ends the run: no
      // reset taken after it, whoever asks, or the run would carry on past its end.
      run_ending_ = run_ending_ || command.kind == CommandKind::JournalFailed || command.source == CommandSource::Signal ||
                    command.source == CommandSource::Program;
      enter_safe_state(command.kind == CommandKind::Stop ? SafeReason::Stopped : SafeReason::JournalFailed,
                       command.source);
      return was_safe ? CommandOutcome::AlreadySafe : CommandOutcome::Done;
    }
    case CommandKind::Reset:
      if (run_ending_) {
        ++counters_.resets_refused;
        return CommandOutcome::RunEnding;
      }
      last_reset_ = try_reset(now_ns);
      ++(last_reset_ == ResetOutcome::Accepted ? counters_.resets_accepted : counters_.resets_refused);
      return outcome_of(last_reset_);
    case CommandKind::SetCoupling:
    case CommandKind::SetForceLimit:
    case CommandKind::SetSpeedLimit:
    case CommandKind::SetDamping:
    case CommandKind::SetFriction:
    case CommandKind::SetSpeedLimiting:
      last_parameter_ = command.kind;
      last_parameter_outcome_ = set_parameter(command.kind, command.value);
      ++parameter_requests_;
      return outcome_of(last_parameter_outcome_);
    case CommandKind::Pause:
      if (safe_reason_ != SafeReason::None || waiting_for_hand_) {
        return CommandOutcome::NotRunning;
      }
      if (paused_) {
        return CommandOutcome::AlreadyPaused;
      }
      paused_ = true;
      return CommandOutcome::Done;
    case CommandKind::Resume:
      // No reset rule here: unlike a reset or a held start, the force never stopped (the hand felt the
      // held tool all along), so nothing jumps; the tool goes on towards the hand at the speed limit,
      // along legal moves, and the mill follows.
      if (!paused_) {
        return CommandOutcome::NotPaused;
      }
      paused_ = false;
      return CommandOutcome::Done;
  }
  return CommandOutcome::Refused;
}

void Controller::take_commands(CommandRing& ring, hal::MonotonicNs now_ns) {
  ring.begin_look(cycle_);
  // Bounded by the ring's capacity: a command pushed while draining waits for the next cycle.
  for (std::size_t i = 0; i < CommandRing::capacity(); ++i) {
    Command command{};
    if (!ring.pop(command)) {
      break;
    }
    const bool parameter = is_parameter(command.kind);
    // Recorded, or not taken: a command the record could not hold would make a replay differ. Only
    // a stop is taken all the same (the safe state it asks for is JournalFull's too).
    if (rings_.command_events.size() >= CommandEventRing::capacity()) {
      enter_safe_state(SafeReason::JournalFull, CommandSource::Cycle);
      if (command.kind == CommandKind::Stop || command.kind == CommandKind::JournalFailed) {
        static_cast<void>(take_command(command, now_ns));
      }
      continue;
    }
    const CommandOutcome outcome = take_command(command, now_ns);
    const CommandEvent event{cycle_,          now_ns,         command.queued_after_cycle,
                             command.kind,    command.source, outcome,
                             parameter ? command.value : 0.0, parameter ? parameter_value(command.kind) : 0.0};
    static_cast<void>(rings_.command_events.push(event));  // room checked above: this is its one producer
  }
}

void Controller::handle_commands(hal::MonotonicNs now_ns) {
  take_commands(rings_.commands, now_ns);
  if (rings_.display_commands != nullptr) {
    take_commands(*rings_.display_commands, now_ns);
  }
  for (std::size_t i = 0; i < MachineEventRing::capacity(); ++i) {
    MachineEvent event{};
    if (!rings_.machine_events.pop(event)) {
      break;
    }
    if (event.kind == MachineEventKind::Fault) {
      enter_safe_state(SafeReason::MachineFault, CommandSource::Machine);
    } else if (event.kind == MachineEventKind::JournalFailed) {
      enter_safe_state(SafeReason::JournalFailed, CommandSource::Machine);
      run_ending_ = true;  // nothing after it would be recorded: no reset
    } else if (event.kind == MachineEventKind::Backlog) {
      backlog_percent_ = event.backlog_percent;
    }
  }
}

void Controller::recall_touched(const Eigen::Vector3d& tip_mm) {
  static_cast<void>(engine::mark_touched(part_, contact_tool_, {tip_mm, Eigen::Vector3d::UnitZ()},
                                         touch_distance_mm(config_), touched_));
}

bool Controller::read_device(hal::MonotonicNs now_ns) {
  hal::HapticSample sample{};
  const hal::ReadResult read = device_.read_sample(now_ns, sample);
  read_ = read;
  if (read.status == hal::ReadStatus::Fresh) {
    read_sample_ = sample;  // the journal keeps what the device said, even if refused below
  }
  fresh_ = false;
  switch (read.status) {
    case hal::ReadStatus::Fresh:
      break;
    case hal::ReadStatus::Stale:
      ++counters_.stale_reads;
      break;
    case hal::ReadStatus::Rejected:
      ++counters_.rejected_samples;
      if (read.reason == hal::HapticFault::SampleOutOfRange) {
        enter_safe_state(SafeReason::PoseOutOfWorkspace);
        return false;
      }
      if (read.reason == hal::HapticFault::SampleNotFinite) {
        enter_safe_state(SafeReason::PoseNotFinite);
        return false;
      }
      break;
    case hal::ReadStatus::Fault:
      enter_safe_state(SafeReason::DeviceFault);
      return false;
  }
  if (read.status != hal::ReadStatus::Fresh) {
    ++cycles_since_fresh_;
    if (cycles_since_fresh_ > config_.stale_periods) {
      enter_safe_state(SafeReason::DeviceStale);
    }
    return have_sample_ && cycles_since_fresh_ <= config_.stale_periods;
  }
  if ((sample.status_bits & hal::haptic_status::kDeviceFault) != 0U) {
    enter_safe_state(SafeReason::DeviceFault);  // the device's own fault: amplifier, encoder
    return false;
  }
  const Eigen::Vector3d position = position_of(sample);
  if (!position.allFinite() || !std::isfinite(sample.angles_rad[0]) || !std::isfinite(sample.angles_rad[1])) {
    enter_safe_state(SafeReason::PoseNotFinite);
    return false;
  }
  if ((position.array() < config_.device_low_mm.array()).any() ||
      (position.array() > config_.device_high_mm.array()).any()) {
    enter_safe_state(SafeReason::PoseOutOfWorkspace);
    return false;
  }
  if (have_sample_) {
    // The farthest a hand can move the handle since the last accepted sample (at least a period's
    // worth, so a sample that was late by a cycle is not a jump).
    const double seconds = static_cast<double>(now_ns - sample_time_ns_) / kNsPerS;
    const double moved = (position - position_of(sample_)).norm();
    if (moved > config_.max_device_speed_mm_per_s * std::max(seconds, 1e-3)) {
      enter_safe_state(SafeReason::PoseJump);
      return false;
    }
    if (seconds > 0.0 && moved > config_.still_speed_mm_per_s * seconds) {
      still_since_ns_ = now_ns;
    }
  } else {
    still_since_ns_ = now_ns;
  }
  sample_ = sample;
  sample_time_ns_ = now_ns;
  have_sample_ = true;
  fresh_ = true;
  cycles_since_fresh_ = 0;
  ++counters_.fresh_samples;
  return true;
}

CycleStatus Controller::step(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns) {
  begin_cycle(now_ns, deadline_ns);
  if (!ready_) {
    enter_safe_state(SafeReason::EngineFault);  // no contact tool (bad tables): never any force
  }
  handle_commands(now_ns);
  const bool usable = read_device(now_ns);
  release_held_start(now_ns, usable);
  const EngineOutcome outcome = run_engine(usable);
  write_force(now_ns, usable, outcome.output);
  publish(now_ns, deadline_ns, outcome);
  return safe_reason_ == SafeReason::None ? CycleStatus::Running : CycleStatus::SafeState;
}

void Controller::begin_cycle(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns) {
  ++cycle_;
  step_start_ns_ = now_ns;
  statistics_.wakeup_latency.add(now_ns - deadline_ns);
  const hal::MonotonicNs period_ns = next_deadline_ns_ - step_deadline_ns_;
  if (next_deadline_ns_ != 0 && period_ns > 0 && deadline_ns > next_deadline_ns_) {
    statistics_.missed_periods += static_cast<std::uint64_t>((deadline_ns - next_deadline_ns_) / period_ns);
  }
  step_deadline_ns_ = deadline_ns;
  if (cycle_ == 1) {
    ramp_start_ns_ = now_ns;
    still_since_ns_ = now_ns;
  }
}

void Controller::release_held_start(hal::MonotonicNs now_ns, bool usable) {
  // A held start: nothing follows the hand until it is held still near the tool, as for a reset, so
  // a handle left resting away from the tool cannot pull the tool (and the mill) the moment it starts.
  if (waiting_for_hand_ && safe_reason_ == SafeReason::None && usable &&
      hand_held_near_tool(now_ns) == ResetOutcome::Accepted) {
    waiting_for_hand_ = false;
    ramp_start_ns_ = now_ns;
    ramping_ = true;
  }
}

Controller::EngineOutcome Controller::run_engine(bool usable) {
  // The device's tip in the world, the contact there, the virtual tool towards it.
  EngineOutcome outcome{position_of(sample_),
                        Eigen::Vector3d::Zero(),
                        {engine::QueryStatus::Ok, 0, 0.0, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()},
                        {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), false, false},
                        engine::RemediationStatus::Stuck};
  outcome.desired_tip_mm = motion::device_to_world(config_.frames, outcome.device_mm);
  if (safe_reason_ != SafeReason::None || !usable || waiting_for_hand_) {
    restart_wall_feel();
    return outcome;
  }
  // The mill's backlog: past half its path the virtual tool slows, to a stop at kBacklogHoldPercent,
  // so the mill catches up; the hand feels the tool lag (a firmer spring) instead of the job ending
  // in a fault. The machine side also reports 100 % while it finds no way for the mill.
  const double backlog_scale =
      std::clamp((kBacklogHoldPercent - backlog_percent_) / (kBacklogHoldPercent - 50.0), 0.0, 1.0);
  if (std::isfinite(config_.max_axis_move_mm) && std::isfinite(config_.max_total_move_mm)) {
    tool_.limit_speed(backlog_scale * config_.max_axis_move_mm, backlog_scale * config_.max_total_move_mm);
  }
  const Eigen::Vector3d& desired = outcome.desired_tip_mm;
  outcome.contact = tool_.contact_at(desired, config_.contact);
  // Paused: the virtual tool stays where it is (the mill holds there); the hand feels it held by the
  // same spring that pulls it towards the tool when the tool lags.
  const engine::RemediationResult moved =
      paused_ ? engine::RemediationResult{engine::RemediationStatus::Stuck, tool_.tip_mm(), 0, 0, false}
              : move_tool(desired, outcome.contact);
  outcome.remediation = moved.status;
  // The damping first: it moves the handle's velocity estimate the penalty reads.
  Eigen::Vector3d added_force = wall_damping(outcome.device_mm, desired, outcome.contact);
  if (config_.feel.speed_limiting == engine::SpeedLimiting::Penalty) {
    added_force += speed_penalty();
  }
  outcome.output = engine::haptic_output(desired, tool_.tip_mm(), outcome.contact, config_.haptic, added_force);
  if (outcome.contact.status != engine::QueryStatus::Ok || moved.status == engine::RemediationStatus::Fault ||
      outcome.output.fault) {
    enter_safe_state(SafeReason::EngineFault);
  } else if (!paused_) {  // held: nothing new touched, and the hand's distance is the operator's own
    static_cast<void>(engine::mark_touched(part_, contact_tool_, tool_.pose(), touch_distance_mm(config_), touched_));
    max_offset_mm_ = std::max(max_offset_mm_, (desired - tool_.tip_mm()).norm());
  }
  return outcome;
}

engine::RemediationResult Controller::move_tool(const Eigen::Vector3d& desired, const engine::ContactResult& contact) {
  if (!(config_.feel.friction > 0.0)) {
    return tool_.step(desired, contact, config_.contact);  // today's: slip, never stick
  }
  const engine::FrictionGoal goal =
      engine::friction_goal(tool_.tip_mm(), desired, contact,
                            config_.haptic.coupling_n_per_device_mm * config_.haptic.device_mm_per_world_mm,
                            config_.feel.friction);
  if (goal.in_contact && tool_on_surface_) {
    // Held only while the tool really rests on the part: the part just below it along the normal (a
    // tool that slid off an edge, or lagged above the face, is not held in the air).
    const Eigen::Vector3d normal = contact.force_n.normalized();
    const engine::ContactResult below =
        tool_.contact_at(tool_.tip_mm() - kRestingProbeMm * normal, config_.contact);
    if (below.status == engine::QueryStatus::Ok && below.penetrating_points > 0) {
      if (goal.sticking) {
        return {engine::RemediationStatus::Stuck, tool_.tip_mm(), 0, 0, false};  // held where it is
      }
      // One more query, at the goal (bounded as the others); the engine still decides what is legal.
      return tool_.step(goal.goal_mm, tool_.contact_at(goal.goal_mm, config_.contact), config_.contact);
    }
  }
  // Not pushed into the part, or the tool not (yet) resting on it: as without friction. It rests once
  // the part stopped it short of the hand, not the speed limit.
  const engine::RemediationResult moved = tool_.step(desired, contact, config_.contact);
  tool_on_surface_ = goal.in_contact && !moved.speed_limited &&
                     (moved.status == engine::RemediationStatus::Slipped ||
                      moved.status == engine::RemediationStatus::Blocked ||
                      moved.status == engine::RemediationStatus::Stuck);
  return moved;
}

Eigen::Vector3d Controller::wall_damping(const Eigen::Vector3d& device_mm, const Eigen::Vector3d& desired,
                                         const engine::ContactResult& contact) {
  const engine::WallFeel& feel = config_.feel;
  if (!(feel.damping_n_s_per_m > 0.0) && !feel.passivity && feel.speed_limiting != engine::SpeedLimiting::Penalty) {
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d stretch_m = 1e-3 * config_.haptic.device_mm_per_world_mm * (tool_.tip_mm() - desired);
  const Eigen::Vector3d handle_m = 1e-3 * device_mm;
  const Eigen::Vector3d last_force(last_command_.force_n[0], last_command_.force_n[1], last_command_.force_n[2]);
  const bool penetrating = contact.penetrating_points > 0;
  // The estimates move with the device's samples (a stale period repeats the last ones), each over
  // the time since the last fresh sample.
  if (fresh_) {
    const double elapsed_s = have_last_handle_ ? static_cast<double>(sample_time_ns_ - last_handle_ns_) / kNsPerS : 0.0;
    static_cast<void>(stretch_rate_.update(stretch_m, elapsed_s));
    static_cast<void>(handle_velocity_.update(handle_m, elapsed_s));
    if (feel.speed_limiting == engine::SpeedLimiting::Penalty) {
      speed_predictor_.sample(elapsed_s);  // with the filter, as it took the sample
    }
    if (feel.passivity) {
      if (penetrating && !was_penetrating_) {
        passivity_.forget_absorbed();  // a contact starts: its balance is its own, less any debt
      } else if (have_last_handle_) {
        // What the device held since the last fresh sample: the last command, after the link's
        // delay, and before it the one before (a delay over a period counts as one period).
        const double late = std::clamp(feel.transport_delay_s / config_.period_s, 0.0, 1.0);
        static_cast<void>(passivity_.observe((1.0 - late) * last_force + late * force_before_, handle_m - last_handle_m_));
      }
      // Relaxed (no stretch, nothing penetrating) and owing nothing: the wall holds nothing.
      if (!penetrating && stretch_m.norm() < 1e-6 && passivity_.energy_j() <= 0.0) {
        passivity_.restart();
      }
    }
    last_handle_m_ = handle_m;
    last_handle_ns_ = sample_time_ns_;
    have_last_handle_ = true;
  }
  force_before_ = last_force;
  was_penetrating_ = penetrating;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  if (!penetrating && stretch_m.norm() < 1e-6) {
    return force;  // nothing in contact, the tool with the hand: no wall to damp
  }
  if (feel.damping_n_s_per_m > 0.0 && penetrating && contact.force_n.allFinite()) {
    // The damper acts both ways while the hand is in the wall (it takes the energy out of the
    // rebound as well as the approach), but a wall only pushes: the damper may take the wall's push
    // along the normal down to zero, never past it into a pull towards the part (Colgate's
    // unilateral virtual wall).
    force = feel.damping_n_s_per_m * stretch_rate_.value();
    const double normal_n = contact.force_n.norm();
    if (normal_n > 0.0) {
      const Eigen::Vector3d normal = contact.force_n / normal_n;
      const Eigen::Vector3d wall_n = config_.haptic.coupling_n_per_device_mm * config_.haptic.device_mm_per_world_mm *
                                         (tool_.tip_mm() - desired) +
                                     contact.force_n;
      const double push_n = std::fmax(wall_n.dot(normal), 0.0);
      const double inward = force.dot(normal);
      if (inward < -push_n) {
        force -= (inward + push_n) * normal;
      }
    }
  }
  if (feel.passivity) {
    force += passivity_.correction(handle_velocity_.value(), config_.period_s, config_.haptic.max_force_n);
  }
  return force;
}

Eigen::Vector3d Controller::speed_penalty() {
  // The cap's per-period moves (world mm), as the speed they allow at the handle (device m/s): the
  // operator's speed limit as it stands, not the backlog's slowing, which comes and goes with the mill.
  const double device_m_per_s = 1e-3 * config_.haptic.device_mm_per_world_mm / config_.period_s;
  // On the velocity past the filter's lag: on the filtered one the slope the law needs rings.
  const Eigen::Vector3d velocity = speed_predictor_.predict(handle_velocity_.value());
  const double limit = engine::mill_speed_along(velocity, device_m_per_s * config_.max_axis_move_mm,
                                                device_m_per_s * config_.max_total_move_mm);
  const Eigen::Vector3d penalty =
      engine::speed_penalty_n(velocity, limit, config_.haptic.max_force_n, config_.feel.speed_penalty_slope_n_s_per_m);
  speed_predictor_.commit(penalty);
  return penalty;
}

void Controller::restart_feel_estimates() {
  stretch_rate_.reset();
  handle_velocity_.reset();
  speed_predictor_.reset();
  passivity_.restart();
  have_last_handle_ = false;
  was_penetrating_ = false;
  force_before_.setZero();
}

void Controller::restart_wall_feel() {
  restart_feel_estimates();
  tool_on_surface_ = false;
}

void Controller::write_force(hal::MonotonicNs now_ns, bool usable, const engine::HapticOutput& output) {
  // Zero in the safe state (already written when it was entered) and while a held start waits for
  // the hand, ramped in after a reset or the start.
  if (safe_reason_ != SafeReason::None || waiting_for_hand_) {
    write_zero_force();  // every cycle: it also beats the host heartbeat the device watches
    return;
  }
  double scale = 1.0;
  if (ramping_) {
    const double elapsed = static_cast<double>(now_ns - ramp_start_ns_) / kNsPerS;
    scale = config_.ramp_time_s > 0.0 ? std::clamp(elapsed / config_.ramp_time_s, 0.0, 1.0) : 1.0;
    ramping_ = scale < 1.0;
  }
  const Eigen::Vector3d force = usable ? Eigen::Vector3d(scale * output.force_n) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d torque = usable ? Eigen::Vector3d(scale * output.torque_nmm) : Eigen::Vector3d::Zero();
  last_command_ = {{force.x(), force.y(), force.z()},
                   {torque.x(), torque.y()},
                   static_cast<std::uint32_t>(cycle_),
                   usable};
  max_force_n_ = std::max(max_force_n_, force.norm());
  if (device_.write_command(last_command_).status == hal::WriteStatus::Fault) {
    enter_safe_state(SafeReason::DeviceFault);
  }
}

void Controller::publish(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns, const EngineOutcome& outcome) {
  if (!rings_.journal.push(build_journal_record(now_ns))) {
    enter_safe_state(SafeReason::JournalFull);  // the record is lost: say so, stop cutting
  }
  // The machine side gets every cycle's virtual tool; falling a whole ring behind is a fault.
  MachineHandoff handoff{cycle_, {}, safe_reason_ != SafeReason::None, paused_};
  copy3(tool_.tip_mm(), handoff.virtual_tip_mm);
  if (!rings_.machine.push(handoff)) {
    enter_safe_state(SafeReason::MachineFault);
  }
  // Last, so that it shows the safe state the journal and the handoff may have just entered.
  if (!rings_.telemetry.push(build_telemetry(now_ns, deadline_ns, outcome))) {
    ++counters_.telemetry_dropped;
  }
}

JournalRecord Controller::build_journal_record(hal::MonotonicNs now_ns) const {
  // The read as the device gave it (a replay feeds it back to the cycle), else the last sample used.
  const hal::HapticSample& recorded = read_.status == hal::ReadStatus::Fresh ? read_sample_ : sample_;
  JournalRecord record{};
  record.cycle = cycle_;
  record.time_ns = now_ns;
  copy3(position_of(recorded), record.device_mm);
  record.angles_rad[0] = recorded.angles_rad[0];
  record.angles_rad[1] = recorded.angles_rad[1];
  record.sample_counter = recorded.sample_counter;
  record.status_bits = static_cast<std::uint16_t>(recorded.status_bits & 0xFFFFU);
  record.read_status = read_.status;
  record.read_reason = read_.reason;
  record.fresh = fresh_;
  copy3(tool_.tip_mm(), record.virtual_tip_mm);
  record.safe_reason = safe_reason_;  // as it stands before the machine handoff
  record.touched_triangles = static_cast<std::uint32_t>(touched_.count());
  for (int i = 0; i < 3; ++i) {
    record.force_n[i] = static_cast<float>(last_command_.force_n[i]);
  }
  record.max_force_n = max_force_n_;
  record.max_offset_mm = max_offset_mm_;
  record.safe_source = safe_source_;
  record.paused = paused_;
  return record;
}

Telemetry Controller::build_telemetry(hal::MonotonicNs now_ns, hal::MonotonicNs deadline_ns,
                                      const EngineOutcome& outcome) const {
  Telemetry telemetry{};
  telemetry.cycle = cycle_;
  telemetry.time_ns = now_ns;
  copy3(outcome.device_mm, telemetry.device_mm);
  copy3(outcome.desired_tip_mm, telemetry.desired_tip_mm);
  copy3(tool_.tip_mm(), telemetry.virtual_tip_mm);
  for (int i = 0; i < 3; ++i) {
    telemetry.force_n[i] = last_command_.force_n[i];
  }
  telemetry.max_depth_mm = outcome.contact.max_depth_mm;
  telemetry.touched_triangles = static_cast<std::uint32_t>(touched_.count());
  telemetry.remediation = outcome.remediation;
  telemetry.safe_reason = safe_reason_;
  telemetry.reset_requests = static_cast<std::uint32_t>(counters_.resets_accepted + counters_.resets_refused);
  telemetry.last_reset = last_reset_;
  telemetry.device_still_s = static_cast<double>(now_ns - still_since_ns_) / kNsPerS;
  telemetry.device_to_tool_mm = (outcome.device_mm - motion::world_to_device(config_.frames, tool_.tip_mm())).norm();
  telemetry.wakeup_ns = now_ns - deadline_ns;
  telemetry.last_compute_ns = last_compute_ns_;
  telemetry.coupling_n_per_device_mm = config_.haptic.coupling_n_per_device_mm;
  telemetry.force_limit_n = config_.haptic.max_force_n;
  telemetry.speed_limit_mm_per_s = config_.max_axis_move_mm / config_.period_s;
  telemetry.damping_n_s_per_m = config_.feel.damping_n_s_per_m;
  telemetry.friction = config_.feel.friction;
  telemetry.speed_limiting = config_.feel.speed_limiting;
  telemetry.parameter_requests = parameter_requests_;
  telemetry.last_parameter = last_parameter_;
  telemetry.last_parameter_outcome = last_parameter_outcome_;
  telemetry.paused = paused_;
  telemetry.safe_source = safe_source_;
  return telemetry;
}

void Controller::finish(hal::MonotonicNs end_ns, hal::MonotonicNs next_deadline_ns) {
  statistics_.compute.add(end_ns - step_start_ns_);
  last_compute_ns_ = end_ns - step_start_ns_;
  next_deadline_ns_ = next_deadline_ns;
  ++statistics_.cycles;
  if (!config_.count_overruns) {
    return;
  }
  if (end_ns > next_deadline_ns) {
    ++statistics_.overruns;
    if (++consecutive_overruns_ > config_.overrun_limit) {
      enter_safe_state(SafeReason::OverrunStorm);
    }
  } else {
    consecutive_overruns_ = 0;
  }
}

}  // namespace stencil::control
