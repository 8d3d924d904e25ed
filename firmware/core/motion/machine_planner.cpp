// The machine waypoint planner.
#include "firmware/core/motion/machine_planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "firmware/core/stencil/sweep.hpp"

namespace stencil::motion {
namespace {

// The six orders of three axes; the link executes the legs of an update in the order chosen.
constexpr std::array<AxisOrder, 6> kOrders = {{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};

// A leg moves one axis by at most one update's budget (tens of steps): a few sub-steps at most.
constexpr int kMaxLegSubSteps = 64;

int sign_of(std::int32_t value) { return value > 0 ? 1 : (value < 0 ? -1 : 0); }

// A straight segment is at most one update's budget long: its length over the sweep's step, plus
// one for the rounding, bounds its sub-steps (capped, so that bad limits cannot make the work
// unbounded: a longer segment is then Limited, so not taken).
constexpr int kMaxStraightSubSteps = 4096;
int straight_sub_steps_for(std::int32_t axis_budget, std::int32_t total_budget, double steps_per_mm, double sweep_step_mm) {
  const double axis = static_cast<double>(std::max(axis_budget, 0));
  const double longest_steps = std::min(std::sqrt(3.0) * axis, static_cast<double>(std::max(total_budget, 0)));
  const double sub_steps = std::ceil(longest_steps / steps_per_mm / sweep_step_mm) + 1.0;
  if (!(sub_steps >= 1.0)) {
    return 1;
  }
  return sub_steps > kMaxStraightSubSteps ? kMaxStraightSubSteps : static_cast<int>(sub_steps);
}

}  // namespace

MachinePlanner::MachinePlanner(const tables::PartTables& part, const MachineFrames& frames, const PlannerLimits& limits)
    : part_(part),
      frames_(frames),
      limits_(limits),
      sweep_step_mm_(engine::sweep_step_mm(part)),
      axis_budget_(static_cast<std::int32_t>(std::floor(limits.speed.max_axis_speed_mm_per_s * limits.update_period_s *
                                                        limits.speed.steps_per_mm))),
      total_budget_(static_cast<std::int32_t>(std::floor(limits.speed.step_rate_steps_per_s * limits.update_period_s))),
      straight_sub_steps_(straight_sub_steps_for(axis_budget_, total_budget_, limits.speed.steps_per_mm, sweep_step_mm_)) {}

void MachinePlanner::homed(const MachineSteps& at, const std::array<int, 3>& approach) {
  homed_ = true;
  axis_ = at;
  motor_ = at;
  for (std::size_t i = 0; i < 3; ++i) {
    slack_side_[i] = approach[i] >= 0 ? 1 : -1;
    take_up_left_[i] = 0;
    take_up_direction_[i] = 0;
  }
  queued_ = 0;
  path_head_ = 0;
  path_size_ = 0;
  newest_mm_ = steps_to_world(frames_, axis_);
}

const Eigen::Vector3d& MachinePlanner::path_at(std::size_t i) const {
  return path_[(path_head_ + i) % kPathCapacity];
}

void MachinePlanner::drop_path_before(std::size_t i) {
  const std::size_t dropped = std::min(i, path_size_);
  path_head_ = (path_head_ + dropped) % kPathCapacity;
  path_size_ -= dropped;
}

PathStatus MachinePlanner::follow(const Eigen::Vector3d& virtual_tip_mm) {
  if (!virtual_tip_mm.allFinite()) {
    return PathStatus::Invalid;
  }
  MachineSteps steps{};
  MachineSteps last{};
  if (!world_to_steps(frames_, virtual_tip_mm, steps) ||
      (path_size_ > 0 && !world_to_steps(frames_, path_at(path_size_ - 1), last))) {
    return PathStatus::Invalid;
  }
  newest_mm_ = virtual_tip_mm;
  if (steps == (path_size_ > 0 ? last : axis_)) {
    return PathStatus::Ignored;  // the mill could not tell it from the newest point
  }
  if (path_size_ == kPathCapacity) {
    return PathStatus::Full;
  }
  path_[(path_head_ + path_size_) % kPathCapacity] = virtual_tip_mm;
  ++path_size_;
  return PathStatus::Added;
}

PlanResult MachinePlanner::result(PlanStatus status) const {
  PlanResult r{status, motor_, axis_, kOrders[0], steps_to_world(frames_, axis_), 0.0, 0};
  r.lag_mm = (newest_mm_ - r.target_mm).norm();
  return r;
}

// Where the tool tip at world_mm is, in (fractional) steps of each axis.
Eigen::Vector3d MachinePlanner::exact_steps(const Eigen::Vector3d& world_mm) const {
  Eigen::Vector3d exact;
  for (int i = 0; i < 3; ++i) {
    exact[i] = frames_.machine_sign[static_cast<std::size_t>(i)] * (world_mm[i] - frames_.home_world_mm[i]) *
               frames_.steps_per_mm;
  }
  return exact;
}

Eigen::Vector3d MachinePlanner::current() const {
  return {static_cast<double>(axis_.axis[0]), static_cast<double>(axis_.axis[1]), static_cast<double>(axis_.axis[2])};
}

// The largest part of the move towards `goal` (steps) that one update allows: no axis beyond its
// speed, all axes together within the step rate, with a step of room on each axis for rounding to
// the grid. True when the whole move fits.
bool MachinePlanner::clip_to_budget(const Eigen::Vector3d& goal, Eigen::Vector3d& clipped) const {
  const Eigen::Vector3d move = goal - current();
  const double largest = move.cwiseAbs().maxCoeff();
  const double total = move.cwiseAbs().sum();
  const double axis_room = static_cast<double>(axis_budget_ - 1);
  const double total_room = static_cast<double>(total_budget_ - 1);
  double scale = 1.0;
  if (largest > axis_room) {
    scale = axis_room / largest;
  }
  if (total * scale > total_room) {
    scale = total_room / total;
  }
  clipped = current() + scale * move;
  return scale == 1.0;
}

// A grid point next to `exact` (steps) that the mill may go to this update: within the budget,
// legal itself, and reached by a legal staircase in some order. The nearest of the cell's corners
// first: the virtual tool runs a micrometre off the part, closer than the grid's own rounding, so
// the nearest corner may be inside where another is not.
bool MachinePlanner::grid_target(const Eigen::Vector3d& wanted, MachineSteps& target, AxisOrder& order,
                                 PlanSearch& search) const {
  if (!wanted.allFinite() || (wanted.cwiseAbs().array() > static_cast<double>(kMaxMachineSteps)).any()) {
    return false;
  }
  // The virtual tool trembles by micrometres against a wall; following every tremor would spend
  // the mill's time taking up backlash. An axis that would go back by only a few steps first tries
  // to stay where it is (if that is legal too: the checks below decide).
  Eigen::Vector3d held = wanted;
  bool holds = false;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double back = (static_cast<double>(axis_.axis[i]) - wanted[e]) * slack_side_[i];
    if (back > 0.0 && back < kReversalDeadbandSteps) {
      held[e] = static_cast<double>(axis_.axis[i]);
      holds = true;
    }
  }
  return (holds && corner_target(held, target, order, search)) || corner_target(wanted, target, order, search);
}

bool MachinePlanner::corner_target(const Eigen::Vector3d& exact, MachineSteps& target, AxisOrder& order,
                                   PlanSearch& search) const {
  const Eigen::Vector3d low = exact.array().floor();
  // Corners that would reverse an axis cost a backlash take-up (tens of steps): after the others.
  std::array<std::pair<double, int>, 8> corners{};
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner = low + Eigen::Vector3d(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    double reversals = 0.0;
    for (std::size_t i = 0; i < 3; ++i) {
      const double move = corner[static_cast<Eigen::Index>(i)] - static_cast<double>(axis_.axis[i]);
      reversals += move * slack_side_[i] < 0.0 ? 1.0 : 0.0;
    }
    corners[static_cast<std::size_t>(c)] = {1e6 * reversals + (corner - exact).squaredNorm(), c};
  }
  std::sort(corners.begin(), corners.end());
  for (const auto& [distance, c] : corners) {
    static_cast<void>(distance);
    MachineSteps corner{};
    std::int32_t total = 0;
    bool within = true;
    for (std::size_t i = 0; i < 3; ++i) {
      corner.axis[i] = static_cast<std::int32_t>(low[static_cast<Eigen::Index>(i)]) + ((c >> i) & 1);
      const std::int32_t move = std::abs(corner.axis[i] - axis_.axis[i]);
      within = within && move <= axis_budget_;
      total += move;
    }
    if (!within || total > total_budget_ || corner == axis_) {
      continue;
    }
    ++search.corners;
    if (engine::check_tip_legal(part_, steps_to_world(frames_, corner)) != engine::Legality::Legal) {
      continue;
    }
    ++search.legal_corners;
    if (legal_order(corner, order, search) >= 0) {
      target = corner;
      return true;
    }
  }
  return false;
}

// The first order whose staircase from the current position to `to` (itself legal) is legal, leg
// by leg; -1 when none is (or the tables fault: the caller cannot tell, and holds either way).
int MachinePlanner::legal_order(const MachineSteps& to, AxisOrder& order, PlanSearch& search) const {
  if (limits_.path == MachinePath::Straight) {
    ++search.staircases;
    ++search.legs;
    const engine::SweepResult segment = engine::check_sweep(part_, steps_to_world(frames_, axis_),
                                                            steps_to_world(frames_, to), sweep_step_mm_,
                                                            straight_sub_steps_);
    if (segment.status != engine::SweepStatus::Legal) {
      return -1;
    }
    order = kOrders[0];
    return 0;
  }
  std::array<bool, 6> seen_paths{};
  for (std::size_t o = 0; o < kOrders.size(); ++o) {
    // Orders that differ only where an axis does not move are the same path.
    std::size_t key = 0;
    for (const std::uint8_t axis : kOrders[o]) {
      if (to.axis[axis] != axis_.axis[axis]) {
        key = key * 3 + axis + 1;
      }
    }
    bool repeated = false;
    for (std::size_t earlier = 0; earlier < o; ++earlier) {
      std::size_t earlier_key = 0;
      for (const std::uint8_t axis : kOrders[earlier]) {
        if (to.axis[axis] != axis_.axis[axis]) {
          earlier_key = earlier_key * 3 + axis + 1;
        }
      }
      repeated = repeated || (seen_paths[earlier] && earlier_key == key);
    }
    if (repeated) {
      continue;
    }
    seen_paths[o] = true;
    ++search.staircases;
    MachineSteps corner = axis_;
    bool legal = true;
    for (const std::uint8_t axis : kOrders[o]) {
      if (corner.axis[axis] == to.axis[axis]) {
        continue;
      }
      MachineSteps next = corner;
      next.axis[axis] = to.axis[axis];
      ++search.legs;
      const engine::SweepResult leg = engine::check_sweep(part_, steps_to_world(frames_, corner),
                                                          steps_to_world(frames_, next), sweep_step_mm_,
                                                          kMaxLegSubSteps);
      if (leg.status != engine::SweepStatus::Legal) {
        legal = false;
        break;
      }
      corner = next;
    }
    if (legal) {
      order = kOrders[o];
      return static_cast<int>(o);
    }
  }
  return -1;
}

PlanResult MachinePlanner::plan(int completed) {
  if (!homed_) {
    return result(PlanStatus::NotHomed);
  }
  queued_ = std::max(0, queued_ - std::max(0, completed));
  if (queued_ >= kMaxQueuedUpdates) {
    return result(PlanStatus::Waiting);
  }
  // A reversal's take-up first: the motors move, the tool does not, so no legality is at stake.
  const auto take_up = [&]() {
    std::int32_t spent = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const std::int32_t amount = std::min({take_up_left_[i], axis_budget_, total_budget_ - spent});
      if (amount <= 0) {
        continue;
      }
      motor_.axis[i] += take_up_direction_[i] * amount;
      take_up_left_[i] -= amount;
      spent += amount;
      if (take_up_left_[i] == 0) {
        slack_side_[i] = take_up_direction_[i];
      }
    }
    ++queued_;
    PlanResult r = result(PlanStatus::TakingUp);
    r.motor_steps = spent;
    return r;
  };
  if (take_up_left_[0] > 0 || take_up_left_[1] > 0 || take_up_left_[2] > 0) {
    return take_up();
  }

  // Follow the virtual tool's path, never a shortcut across it: the farthest point along the path
  // whose move from here fits this update, then earlier points, and last of all the path's first
  // point, to which some staircase is always legal (kFollowStandoff's argument above
  // follow_standoff_needed_mm). Only path points: the mill stays near one, which the argument needs.
  if (!pass_points_at_hand()) {
    return result(PlanStatus::Fault);
  }
  if (path_size_ == 0) {
    return result(PlanStatus::AtGoal);
  }
  std::size_t within = 0;  // path points [0, within) are reachable this update
  Eigen::Vector3d clipped;
  while (within < path_size_ && clip_to_budget(exact_steps(path_at(within)), clipped)) {
    ++within;
  }
  MachineSteps target{};
  AxisOrder order{};
  std::size_t passed = 0;  // path points the mill is done with once at target
  bool found = false;
  PlanSearch search{};
  search.next_point_mm = path_at(0);
  for (int candidate = 0; candidate <= kMaxCandidates && !found; ++candidate) {
    Eigen::Vector3d exact;
    if (within > 0) {
      const std::size_t index = candidate_index(candidate, within);
      if (candidate > 0 && index == candidate_index(candidate - 1, within)) {
        break;  // the first point was tried: nothing is left to try
      }
      exact = exact_steps(path_at(index));
      passed = index + 1;
    } else {
      // Not even the first point is in reach (a gap in the path, which the cycle never leaves):
      // part of the way towards it, as far as the budget goes, then a half of that, a quarter, ...
      static_cast<void>(clip_to_budget(exact_steps(path_at(0)), exact));
      exact = current() + (exact - current()) / std::ldexp(1.0, candidate);
      passed = 0;
    }
    ++search.candidates;
    found = grid_target(exact, target, order, search);
  }
  if (found) {
    bool reverses = false;
    for (std::size_t i = 0; i < 3; ++i) {
      const int direction = sign_of(target.axis[i] - axis_.axis[i]);
      if (direction != 0 && direction != slack_side_[i]) {
        if (limits_.backlash_steps[i] > 0) {
          take_up_left_[i] = limits_.backlash_steps[i];
          take_up_direction_[i] = direction;
          reverses = true;
        } else {
          slack_side_[i] = direction;
        }
      }
    }
    if (reverses) {
      return take_up();  // the move itself comes once the slack is gone (and is planned afresh)
    }
    std::int32_t moved = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      motor_.axis[i] += target.axis[i] - axis_.axis[i];
      moved += std::abs(target.axis[i] - axis_.axis[i]);
    }
    axis_ = target;
    drop_path_before(passed);
    ++queued_;
    PlanResult r = result(PlanStatus::Moved);
    r.order = order;
    r.motor_steps = moved;
    return r;
  }
  blocked_search_ = search;
  return result(PlanStatus::Blocked);
}

bool MachinePlanner::pass_points_at_hand() {
  while (path_size_ > 0) {
    MachineSteps goal{};
    if (!world_to_steps(frames_, path_at(0), goal)) {
      return false;
    }
    const Eigen::Vector3d exact = exact_steps(path_at(0));
    bool at_hand = true;
    for (std::size_t i = 0; i < 3; ++i) {
      at_hand = at_hand && std::abs(exact[static_cast<Eigen::Index>(i)] - static_cast<double>(axis_.axis[i])) < 1.0;
    }
    if (!at_hand) {
      return true;
    }
    drop_path_before(1);
  }
  return true;
}

// Candidates walk back from the farthest reachable point, 1, 2, 4, 8, ... points at a time, and end
// on the path's first point (index 0): kMaxCandidates + 1 of them reach back over the whole path.
std::size_t MachinePlanner::candidate_index(int candidate, std::size_t within) {
  if (candidate >= kMaxCandidates) {
    return 0;
  }
  const std::size_t back = candidate == 0 ? 0 : (std::size_t{1} << static_cast<unsigned>(candidate - 1));
  return back >= within ? 0 : within - 1 - back;
}

}  // namespace stencil::motion
