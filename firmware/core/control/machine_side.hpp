// MachineSide: what the machine thread does at each machine update (about 30 Hz): takes the
// cycle's virtual tool positions into the planner's path, sends the next legal target to the mill,
// and on the cycle's safe state holds the feed and stops the machine. Not the 1 kHz cycle: the link
// may block up to its deadlines. Allocation-free all the same.
#pragma once

#include <cstdint>

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/machine_record.hpp"
#include "firmware/core/motion/machine_planner.hpp"
#include "hal/clock.hpp"  // MonotonicNs
#include "hal/machine_link.hpp"

namespace stencil::control {

enum class MachineSideState : std::uint8_t {
  NotStarted,  // start() not called or it failed
  Cutting,     // homed, spindle on, following the virtual tool
  Stopped,     // the cycle's safe state (or a fault here): held, spindle and drivers off
};

struct MachineSideStatistics {
  std::uint64_t updates = 0;      // targets sent
  std::uint64_t take_ups = 0;     // of which only took up backlash
  std::uint64_t blocked = 0;      // updates with no legal staircase (held)
  double max_lag_mm = 0.0;        // virtual tool to the mill's target, world
  double last_lag_mm = 0.0;       // the same at the newest update
  std::int64_t motor_steps = 0;   // all axes, take-up included
  std::uint64_t held_for_record = 0;  // updates the mill held: the newest target not yet in the record
  std::uint64_t holds = 0;            // the operator's feed holds (pauses) taken to the link
  std::uint64_t held_updates = 0;     // updates in them: nothing sent
};

class MachineSide {
 public:
  // The rings are the cycle's; part, link and rings must outlive this object.
  MachineSide(const tables::PartTables& part, hal::MachineLink& link, const motion::MachineFrames& frames, const motion::PlannerLimits& limits,
              MachineHandoffRing& from_cycle, MachineEventRing& to_cycle);

  // Init: wakes the controller, homes on the switches, turns the spindle on. False with the link's
  // fault on failure (nothing moves then). home() then start_spindle() are the same in two steps,
  // for a rig whose operator confirms before the spindle starts.
  [[nodiscard]] bool start(hal::MonotonicNs deadline_ns) { return home(deadline_ns) && start_spindle(deadline_ns); }
  [[nodiscard]] bool home(hal::MonotonicNs deadline_ns);
  [[nodiscard]] bool start_spindle(hal::MonotonicNs deadline_ns);

  // One machine update, by update_deadline_ns: drains the cycle's handoffs, then plans and sends
  // at most one target. A fault here is reported to the cycle and stops the machine.
  void update(hal::MonotonicNs update_deadline_ns);

  // The end of a job: holds the feed and stops the machine if it is still cutting (no fault is
  // reported; the cycle has stopped already).
  void shut_down(hal::MonotonicNs deadline_ns) {
    if (state_ == MachineSideState::Cutting) {
      stop(deadline_ns, false);
    }
  }

  [[nodiscard]] MachineSideState state() const { return state_; }
  [[nodiscard]] hal::MachineFault fault() const { return link_.status().fault; }
  [[nodiscard]] const MachineSideStatistics& statistics() const { return statistics_; }
  // Queued points of the virtual tool's path the mill has not reached yet (0: drained).
  [[nodiscard]] std::size_t path_left() const { return planner_.path_size(); }
  [[nodiscard]] bool at_goal() const { return at_goal_; }
  // The operator's feed hold is on at the link (the cycle is paused).
  [[nodiscard]] bool held() const { return held_; }
  [[nodiscard]] const motion::MachinePlanner& planner() const { return planner_; }

  // The model of the machined stock this side keeps from the targets it sends (null: none). Set
  // before start(); this side is its only writer, readers look once the machine thread is done or
  // between updates on the same thread.
  void keep_stock_model(CommandedStock* stock) { stock_ = stock; }
  // Every homing and target goes to `recorder` before it is acted on (null: none): a target is sent
  // once the recorder has it written, and until then the mill holds. Set before start().
  void record_to(MachineRecorder* recorder) { recorder_ = recorder; }
  // The recorder refused a record, or kept a target unwritten past kMaxUnrecordedUpdates: the
  // machine did not start, or was stopped and the cycle told (JournalFailed).
  [[nodiscard]] bool record_failed() const { return record_failed_; }
  // More updates than this in a row holding a target the record has not written (4 s at 30 Hz, as
  // long as the cycle's journal ring lasts on a stalled disk) is a journal fault; fewer only hold
  // the mill (slow storage costs time, not the cut).
  static constexpr int kMaxUnrecordedUpdates = 120;
  // More updates than this in a row with no legal staircase (3 s at 30 Hz) is a fault: stalled().
  // With the standoff it cannot happen while the virtual tool moves legally (the planner's
  // argument); it stays as the last guard. Until then the virtual tool is held (the backlog at 100 %).
  static constexpr int kMaxBlockedUpdates = 90;
  [[nodiscard]] bool stalled() const { return stalled_; }
  // Where a stall happened: the virtual tool's newest tip, the mill's (commanded) tip, and what the
  // last search tried (valid once stalled()).
  struct Stall {
    Eigen::Vector3d virtual_tip_mm;
    Eigen::Vector3d mill_tip_mm;
    motion::PlanSearch search;
  };
  [[nodiscard]] const Stall& stall() const { return stall_; }
  // After a stop: whether the link confirmed the spindle and drivers off (false: they may still be
  // on, whatever the cycle's safe state says; the operator must cut the mill's power).
  [[nodiscard]] bool stop_confirmed() const { return stop_confirmed_; }
  // Where the last target sent puts the tool tip (world mm): home until the first.
  [[nodiscard]] const Eigen::Vector3d& commanded_tip_mm() const { return commanded_tip_mm_; }

 private:
  // report: the event the cycle gets first (Fault, JournalFailed), or nothing when it stopped us.
  void stop(hal::MonotonicNs deadline_ns, bool report_fault, MachineEventKind report = MachineEventKind::Fault);
  // Sends a planned target and cuts the stock model along its legs; false when the link failed (stopped).
  [[nodiscard]] bool send(const motion::PlanResult& plan, hal::MonotonicNs deadline_ns);

  hal::MachineLink& link_;
  MachineHandoffRing& from_cycle_;
  MachineEventRing& to_cycle_;
  motion::MachinePlanner planner_;
  MachineSideState state_ = MachineSideState::NotStarted;
  std::uint64_t moves_seen_ = 0;
  bool at_goal_ = false;
  bool held_ = false;
  MachineSideStatistics statistics_;
  CommandedStock* stock_ = nullptr;
  MachineRecorder* recorder_ = nullptr;
  bool record_failed_ = false;
  // A target queued for the record and not yet written: planned, not sent (the planner counts it
  // queued, so nothing else is planned before it goes).
  motion::PlanResult unrecorded_{};
  bool holding_unrecorded_ = false;
  int unrecorded_updates_ = 0;
  int blocked_in_a_row_ = 0;
  bool stalled_ = false;
  Stall stall_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {}};
  bool stop_confirmed_ = false;
  Eigen::Vector3d commanded_tip_mm_;
};

}  // namespace stencil::control
