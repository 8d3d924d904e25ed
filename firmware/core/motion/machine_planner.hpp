// The machine waypoint planner: turns the virtual tool's legal path into the mill's targets, one
// per machine update, so that what the mill actually does (straight segments, one axis at a time
// inside each) is legal too, within its speed, inside its travel, with backlash taken up.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/motion/speed_limit.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::motion {

// Going back fewer steps than this on an axis is first tried as not going back at all (see
// MachinePlanner::grid_target): the virtual tool trembles by micrometres against a wall, and each
// reversal costs a backlash take-up. So a held axis may end up to this many steps (plus one of
// rounding) from the virtual tool.
inline constexpr double kReversalDeadbandSteps = 4.0;

// How the mill moves between two targets, so the planner checks the path it really takes.
enum class MachinePath : std::uint8_t {
  Staircase,  // one axis at a time, in the order the planner chose (the CY545 steps so)
  Straight,   // one coordinated straight segment (LinuxCNC's G1 in exact-path mode, G61)
};

struct PlannerLimits {
  MachineSpeed speed;
  double update_period_s;                     // one machine update (1/30 s on the rig)
  std::array<std::int32_t, 3> backlash_steps; // slack per axis, taken up on every reversal (0 where
                                              // the controller compensates its own, as LinuxCNC does)
  MachinePath path = MachinePath::Staircase;
};

// Why the mill can always follow a virtual tool that keeps a standoff s from the part
// (engine/standoff.hpp), with h one step and v the most the virtual tool moves along an axis in a
// cycle (v <= h):
//  - The path's points are the virtual tool's tips, each legal for the tool grown by s, so the real
//    tool is legal anywhere within s of one of them (the grown tool contains the real one moved by
//    up to s). A point is stored once it rounds to another step than the last stored one, so on
//    each axis it is less than h + v from it.
//  - The mill only ever goes to a grid point of a path point's cell (a corner, each axis within h
//    of it) or, on an axis it holds against a small reversal, stays less than
//    kReversalDeadbandSteps + 1 steps from it; that point is then the mill's anchor a: on each axis
//    the mill g is less than (kReversalDeadbandSteps + 1) h from a. Points whose cell has g as a
//    corner are passed without moving (g is within h of them).
//  - The path's next point p is always a candidate (the last tried). Take the corner c of p's cell
//    inside the workspace (the workspace's faces count too): each axis of c is within h of p, so
//    less than 2h + v from a. Every point of a staircase from g to c, in any order, lies axis by
//    axis between g and c, so less than max(kReversalDeadbandSteps + 1, 2 + v/h) h from a on each
//    axis: within sqrt(3) times that of a, which is within s: legal, as is c. The move is under
//    kReversalDeadbandSteps + 4 steps per axis: inside one update's budget (follow_fallback_fits).
// So some staircase is always legal, the planner finds it (it tries every corner and order), and
// the mill never stalls while the virtual tool moves legally. A mill that moves in straight
// segments (MachinePath::Straight) is covered by the same argument: the segment from g to c lies
// axis by axis between them too. The standoff that takes:
constexpr double follow_standoff_needed_mm(double steps_per_mm, double max_axis_move_per_cycle_mm) {
  const double step_mm = 1.0 / steps_per_mm;
  if (!(max_axis_move_per_cycle_mm <= step_mm)) {
    return 1e300;  // the argument needs v <= h: no standoff is enough for it
  }
  const double held = kReversalDeadbandSteps + 1.0;
  const double next = 2.0 + max_axis_move_per_cycle_mm / step_mm;
  return 1.7320508075688772 * (held > next ? held : next) * step_mm;
}
// One update's budget covers the fallback's move (with the step of room clip_to_budget keeps).
constexpr bool follow_fallback_fits(const PlannerLimits& limits) {
  const double per_axis = kReversalDeadbandSteps + 4.0;
  return limits.speed.max_axis_speed_mm_per_s * limits.update_period_s * limits.speed.steps_per_mm >= per_axis + 1.0 &&
         limits.speed.step_rate_steps_per_s * limits.update_period_s >= 3.0 * per_axis + 1.0;
}

// The order in which the mill moves its axes inside one update (the CY545 steps one axis at a
// time): the machine link must execute the legs in this order, since only this staircase was
// checked.
using AxisOrder = std::array<std::uint8_t, 3>;

enum class PlanStatus : std::uint8_t {
  Moved,        // a new target: the tool moves
  TakingUp,     // a new target that only takes up backlash (motors move, the tool does not)
  AtGoal,       // nothing to do: the mill is where the virtual tool is
  Waiting,      // two updates are already queued: nothing new until the link completes one
  Blocked,      // no legal staircase to any point of the path within this update: holding
  NotHomed,     // no target before homed()
  Fault,        // bad numbers or damaged tables: stop the machine
};

// What the search of the last update that found no way tried (the stall's report says it).
struct PlanSearch {
  int candidates = 0;       // path points (or part-way points) tried
  int corners = 0;          // their grid corners within the budget
  int legal_corners = 0;    // of which the mill may stand on
  int staircases = 0;       // orders tried towards those
  int legs = 0;             // one-axis legs checked along them
  Eigen::Vector3d next_point_mm = Eigen::Vector3d::Zero();  // the path's first point not yet reached
};

struct PlanResult {
  PlanStatus status;
  MachineSteps motor_target;   // what to send: axis target plus backlash compensation
  MachineSteps axis_target;    // where the tool will be, in steps
  AxisOrder order;             // legs in this order
  Eigen::Vector3d target_mm;   // axis_target in the world
  double lag_mm;               // distance from the newest virtual tool to axis_target
  std::int32_t motor_steps;    // steps of all axes in this update (take-up included)
};

enum class PathStatus : std::uint8_t {
  Added,    // stored as the path's newest point
  Ignored,  // on the same step as the newest point: nothing to store
  Full,     // the mill is too far behind the virtual tool: a fault (the cycle's speed limit should
            // make this impossible)
  Invalid,  // not finite, or beyond the steps the CY545 can count
};

// Owned by the machine side: its own read-only view of the tables, its own engine scratch (each
// legality query), never the touched set. Allocation-free after construction; plan() tries at most
// kMaxCandidates + 1 candidates x 8 corners x 6 orders x 3 legs sweeps, each of a bounded number of
// sub-steps (MachinePath::Straight: candidates x 8 corners x 1 sweep of at most straight_sub_steps()).
class MachinePlanner {
 public:
  static constexpr std::size_t kPathCapacity = 4096;  // points at least a step apart: seconds of motion
  static constexpr int kMaxQueuedUpdates = 2;
  static constexpr int kMaxCandidates = 14;

  MachinePlanner(const tables::PartTables& part, const MachineFrames& frames, const PlannerLimits& limits);

  // The machine has been homed and stands at `at` (steps), its last motion on each axis in
  // direction approach[i] (+1 or -1: where the slack is). The path restarts there; nothing queued.
  void homed(const MachineSteps& at, const std::array<int, 3>& approach);

  // The virtual tool's (legal) tip, as often as the cycle hands it over; stored when it is on
  // another step than the newest stored point.
  [[nodiscard]] PathStatus follow(const Eigen::Vector3d& virtual_tip_mm);

  // One machine update. `completed`: how many earlier targets the link has finished since the last
  // call. Returns the next target to queue, or why there is none.
  [[nodiscard]] PlanResult plan(int completed);

  [[nodiscard]] const MachineSteps& axis_steps() const { return axis_; }
  [[nodiscard]] const MachineSteps& motor_steps() const { return motor_; }
  [[nodiscard]] std::size_t path_size() const { return path_size_; }
  [[nodiscard]] int queued() const { return queued_; }
  // The newest virtual tool tip handed to follow().
  [[nodiscard]] const Eigen::Vector3d& newest_mm() const { return newest_mm_; }
  // The most sub-steps a straight segment's sweep checks: enough for one update's longest move.
  [[nodiscard]] int straight_sub_steps() const { return straight_sub_steps_; }
  // What the last plan() that returned Blocked tried.
  [[nodiscard]] const PlanSearch& last_blocked_search() const { return blocked_search_; }

 private:
  [[nodiscard]] const Eigen::Vector3d& path_at(std::size_t i) const;
  void drop_path_before(std::size_t i);
  [[nodiscard]] Eigen::Vector3d exact_steps(const Eigen::Vector3d& world_mm) const;
  [[nodiscard]] Eigen::Vector3d current() const;
  [[nodiscard]] bool clip_to_budget(const Eigen::Vector3d& goal, Eigen::Vector3d& clipped) const;
  [[nodiscard]] bool grid_target(const Eigen::Vector3d& wanted, MachineSteps& target, AxisOrder& order,
                                 PlanSearch& search) const;
  [[nodiscard]] bool corner_target(const Eigen::Vector3d& exact, MachineSteps& target, AxisOrder& order,
                                   PlanSearch& search) const;
  [[nodiscard]] int legal_order(const MachineSteps& to, AxisOrder& order, PlanSearch& search) const;
  // Drops the path's points the mill stands at a corner of (it is within a step of them).
  [[nodiscard]] bool pass_points_at_hand();
  // The path's point `back` candidates before the farthest reachable one (`within` of them reachable).
  [[nodiscard]] static std::size_t candidate_index(int candidate, std::size_t within);
  [[nodiscard]] PlanResult result(PlanStatus status) const;

  const tables::PartTables& part_;
  MachineFrames frames_;
  PlannerLimits limits_;
  double sweep_step_mm_;
  std::int32_t axis_budget_;   // steps one axis may make in an update (its speed)
  std::int32_t total_budget_;  // steps all axes together may make in an update (the step rate)
  int straight_sub_steps_;
  bool homed_ = false;
  MachineSteps axis_{};                 // commanded tool position, steps
  MachineSteps motor_{};                // commanded motor position, steps
  std::array<int, 3> slack_side_{};     // +1: last moved +, the slack is behind; -1 the other way
  std::array<std::int32_t, 3> take_up_left_{};  // steps of a reversal's take-up not yet commanded
  std::array<int, 3> take_up_direction_{};
  int queued_ = 0;
  std::array<Eigen::Vector3d, kPathCapacity> path_;  // ring, oldest at path_head_
  std::size_t path_head_ = 0;
  std::size_t path_size_ = 0;
  Eigen::Vector3d newest_mm_ = Eigen::Vector3d::Zero();
  PlanSearch blocked_search_{};
};

}  // namespace stencil::motion
