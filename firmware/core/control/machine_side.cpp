// The machine update: path in, one target out, stop on the safe state.
#include "firmware/core/control/machine_side.hpp"

#include <algorithm>

namespace stencil::control {

MachineSide::MachineSide(const tables::PartTables& part, hal::MachineLink& link, const motion::MachineFrames& frames, const motion::PlannerLimits& limits,
                         MachineHandoffRing& from_cycle, MachineEventRing& to_cycle)
    : link_(link), from_cycle_(from_cycle), to_cycle_(to_cycle), planner_(part, frames, limits),
      commanded_tip_mm_(frames.home_world_mm) {}

bool MachineSide::home(hal::MonotonicNs deadline_ns) {
  // The homing is in the record before anything moves: from it on the tool is at home, whatever the
  // record said before (a resumed job starts here). Not recorded: nothing moves, the spindle stays off.
  if (recorder_ != nullptr && !recorder_->homed(deadline_ns)) {
    record_failed_ = true;
    return false;
  }
  if (!link_.start(deadline_ns).done || !link_.home(deadline_ns).done) {
    return false;
  }
  planner_.homed({{0, 0, 0}}, link_.home_approach());
  moves_seen_ = link_.status().moves_done;
  return true;
}

bool MachineSide::start_spindle(hal::MonotonicNs deadline_ns) {
  if (!link_.status().homed || !link_.set_spindle(true, deadline_ns).done) {
    return false;
  }
  state_ = MachineSideState::Cutting;
  return true;
}

void MachineSide::stop(hal::MonotonicNs deadline_ns, bool report_fault, MachineEventKind report) {
  if (report_fault) {
    // A full event ring means the cycle already has a fault to read: it is in its safe state.
    static_cast<void>(to_cycle_.push({.kind = report, .fault = link_.status().fault}));
  }
  if (state_ == MachineSideState::Stopped) {
    return;
  }
  state_ = MachineSideState::Stopped;
  link_.hold();
  held_ = false;  // stopped, not the operator's hold: a readout must not show it held
  // The link tries whatever fault it has latched, and says whether the outputs are confirmed off.
  stop_confirmed_ = link_.stop(deadline_ns).done;
  static_cast<void>(to_cycle_.push({.kind = MachineEventKind::Stopped, .stop_confirmed = stop_confirmed_}));
}

void MachineSide::update(hal::MonotonicNs update_deadline_ns) {
  // Every handoff since the last update, in order: the planner follows the virtual tool's path.
  bool safe_state = false;
  bool paused = held_;  // no handoff since the last update: as it was
  for (std::size_t i = 0; i < MachineHandoffRing::capacity(); ++i) {
    MachineHandoff handoff{};
    if (!from_cycle_.pop(handoff)) {
      break;
    }
    safe_state = safe_state || handoff.safe_state;
    paused = handoff.paused;  // the newest says
    if (state_ == MachineSideState::Cutting && !handoff.safe_state) {
      const Eigen::Vector3d tip(handoff.virtual_tip_mm[0], handoff.virtual_tip_mm[1], handoff.virtual_tip_mm[2]);
      if (planner_.follow(tip) == motion::PathStatus::Full) {
        stop(update_deadline_ns, true);  // the mill fell too far behind to follow the path
      }
    }
  }
  if (state_ != MachineSideState::Cutting) {
    return;
  }
  // The backlog, so the cycle can slow the virtual tool before the path fills (which is a fault).
  // Only while the ring has room to spare: a fault's event must always find a slot.
  // A mill that found no way at its last update reports 100 %: the cycle holds the virtual tool
  // (a firmer spring for the hand) until it has one again.
  if (to_cycle_.size() < MachineEventRing::capacity() / 2) {
    const auto percent = static_cast<std::uint8_t>(
        blocked_in_a_row_ > 0 ? 100
                              : std::min<std::size_t>(100, 100 * planner_.path_size() / motion::MachinePlanner::kPathCapacity));
    static_cast<void>(to_cycle_.push({.kind = MachineEventKind::Backlog, .backlog_percent = percent}));
  }
  if (safe_state) {
    stop(update_deadline_ns, false);
    return;
  }
  if (!link_.keep_alive(update_deadline_ns).done) {  // the watchdog relay's heartbeat, every update
    stop(update_deadline_ns, true);
    return;
  }
  // The operator's feed hold: the link refuses moves from here (each lasts at most an update, so the
  // mill is still by the next one); nothing is planned, recorded or sent until it is lifted, and then
  // the mill carries on along the path it held, with no homing.
  if (paused) {
    if (!held_) {
      link_.hold();
      held_ = true;
      ++statistics_.holds;
    }
    ++statistics_.held_updates;
    return;
  }
  if (held_) {
    link_.resume();
    held_ = false;
  }
  // A target queued for the record at an earlier update goes out in this one once it is written;
  // until then the mill holds (this update keeps its deadline: nothing here waits on the record's
  // storage), and a journal fault only past the bound.
  if (holding_unrecorded_ && !recorder_->written()) {
    ++statistics_.held_for_record;
    if (++unrecorded_updates_ > kMaxUnrecordedUpdates) {
      record_failed_ = true;
      stop(update_deadline_ns, true, MachineEventKind::JournalFailed);
    }
    return;
  }
  // Written: it goes below, after the next target is planned and queued, so that the records thread
  // writes that one while the mill runs this one (the planner counts the held target as queued).
  const bool send_held = holding_unrecorded_;
  const motion::PlanResult held = unrecorded_;
  holding_unrecorded_ = false;
  const std::uint64_t moves_done = link_.status().moves_done;
  const auto completed = static_cast<int>(std::min<std::uint64_t>(moves_done - moves_seen_, 8));
  moves_seen_ = moves_done;
  const motion::PlanResult plan = planner_.plan(completed);
  if (plan.status != motion::PlanStatus::Blocked) {
    blocked_in_a_row_ = 0;
  }
  statistics_.max_lag_mm = std::max(statistics_.max_lag_mm, plan.lag_mm);
  statistics_.last_lag_mm = plan.lag_mm;
  at_goal_ = plan.status == motion::PlanStatus::AtGoal;
  switch (plan.status) {
    case motion::PlanStatus::Moved:
    case motion::PlanStatus::TakingUp: {
      if (recorder_ != nullptr) {
        // Its place among the targets sent: after the held one, when that goes in this update.
        MachineCommandRecord record{statistics_.updates + (send_held ? 1U : 0U), update_deadline_ns, {}, {3, 3, 3}, {}};
        for (int i = 0; i < 3; ++i) {
          record.motor_target[i] = plan.motor_target.axis[static_cast<std::size_t>(i)];
          record.order[i] = plan.order[static_cast<std::size_t>(i)];
          record.target_tip_mm[i] = plan.target_mm[i];
        }
        if (!recorder_->command(record)) {
          record_failed_ = true;  // not recorded: not sent either, so the record still holds all that was cut
          stop(update_deadline_ns, true, MachineEventKind::JournalFailed);
          return;
        }
        // Not yet in the file (the records thread writes it within microseconds on a healthy disk),
        // or the held target goes in this update (one target an update, as ever): it waits.
        if (send_held || !recorder_->written()) {
          unrecorded_ = plan;
          holding_unrecorded_ = true;
          unrecorded_updates_ = 0;
          break;
        }
      }
      static_cast<void>(send(plan, update_deadline_ns));  // a link that fails stops the machine
      break;
    }
    case motion::PlanStatus::Blocked:
      ++statistics_.blocked;
      // No legal way for the mill along the tool's path for this long: a fault, not a silent stall
      // (with the backlog holding the virtual tool, nothing would ever move again).
      if (++blocked_in_a_row_ > kMaxBlockedUpdates) {
        stalled_ = true;
        stall_ = {planner_.newest_mm(), commanded_tip_mm_, planner_.last_blocked_search()};
        stop(update_deadline_ns, true);
      }
      break;
    case motion::PlanStatus::Fault:
    case motion::PlanStatus::NotHomed:
      stop(update_deadline_ns, true);
      break;
    case motion::PlanStatus::AtGoal:
    case motion::PlanStatus::Waiting:
      break;
  }
  if (send_held && state_ == MachineSideState::Cutting) {
    static_cast<void>(send(held, update_deadline_ns));  // a link that fails stops the machine
  }
}

bool MachineSide::send(const motion::PlanResult& plan, hal::MonotonicNs deadline_ns) {
  const hal::MachineResult moved = link_.move({plan.motor_target.axis, plan.order, true}, deadline_ns);
  if (!moved.done) {
    stop(deadline_ns, true);
    return false;
  }
  ++statistics_.updates;
  statistics_.take_ups += plan.status == motion::PlanStatus::TakingUp ? 1 : 0;
  // The tool goes there one axis at a time, in the plan's order: each leg cuts the model.
  for (const std::uint8_t axis : plan.order) {
    if (axis > 2) {
      continue;
    }
    Eigen::Vector3d next = commanded_tip_mm_;
    next[axis] = plan.target_mm[axis];
    if (stock_ != nullptr && next != commanded_tip_mm_) {
      stock_->cut(commanded_tip_mm_, next);
    }
    commanded_tip_mm_ = next;
  }
  commanded_tip_mm_ = plan.target_mm;
  statistics_.motor_steps += plan.motor_steps;
  return true;
}

}  // namespace stencil::control
