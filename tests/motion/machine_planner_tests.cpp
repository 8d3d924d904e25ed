// The waypoint planner against the hex prism, with the mill's staircase checked independently at a
// fine pitch and a deadband model of backlash standing in for the real screws.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/motion/machine_planner.hpp"
#include "firmware/core/motion/speed_limit.hpp"
#include "firmware/core/stencil/standoff.hpp"
#include "firmware/core/stencil/sweep.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/support/gouge_oracle.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil;
using namespace stencil::motion;

namespace {

const Eigen::Vector3d kHome(25.0, 12.5, 20.0);  // above the prism

MachineFrames sherline_frames() { return {10.0, Eigen::Vector3d::Zero(), kHome, {-1, -1, 1}, 640.0}; }

PlannerLimits sherline_limits() { return {{1.4, 1000.0, 640.0}, 1.0 / 30.0, {80, 32, 80}}; }


struct Loaded {
  tablegen::TableBytes bytes;
  tables::PartTables part{};
  Loaded() : bytes(test::make_table(test::default_part(), test::default_job_options(2))) {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
  }
};


// The mill's own screws: an axis follows its motor only once the slack on that side is taken up.
struct DeadbandAxis {
  double motor = 0.0;
  double axis = 0.0;
  double backlash = 0.0;
  void move_motor_to(double target) {
    motor = target;
    axis = std::clamp(axis, motor - backlash, motor);  // pushed from either side of the gap
  }
};

// Every point of the staircase the mill follows from `from` to `to` in `order`, checked every 2 um
// by the engine and by the exact triangle oracle.
void check_staircase(const tables::PartTables& part, const MachineFrames& frames, const MachineSteps& from,
                     const MachineSteps& to, const AxisOrder& order) {
  MachineSteps corner = from;
  for (const std::uint8_t axis : order) {
    const std::int32_t start = corner.axis[axis];
    const std::int32_t end = to.axis[axis];
    const std::int32_t direction = end > start ? 1 : -1;
    for (std::int32_t s = start; s != end + direction && start != end; s += direction) {
      corner.axis[axis] = s;
      const Eigen::Vector3d at = steps_to_world(frames, corner);
      CHECK(engine::check_tip_legal(part, at) == engine::Legality::Legal);
      CHECK(test::ball_end_gouge_mm(part, at) <= part.header.gouge_bound_mm + 1e-5);
    }
    corner.axis[axis] = end;
  }
}

// Every point of the straight segment from `from` to `to`, checked every 2 um the same way.
void check_straight(const tables::PartTables& part, const MachineFrames& frames, const MachineSteps& from,
                    const MachineSteps& to) {
  const Eigen::Vector3d a = steps_to_world(frames, from);
  const Eigen::Vector3d b = steps_to_world(frames, to);
  const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.002)));
  for (int k = 0; k <= pieces; ++k) {
    const Eigen::Vector3d at = a + (b - a) * (static_cast<double>(k) / pieces);
    CHECK(engine::check_tip_legal(part, at) == engine::Legality::Legal);
    CHECK(test::ball_end_gouge_mm(part, at) <= part.header.gouge_bound_mm + 1e-5);
  }
}

// A mill that moves like LinuxCNC's: the CY545 rig's speed per axis, but no limit on the sum of the
// axes' steps (a coordinated move), no backlash (LinuxCNC takes its own up), straight segments.
PlannerLimits straight_limits() { return {{1.4, 3000.0, 640.0}, 1.0 / 30.0, {0, 0, 0}, MachinePath::Straight}; }

struct Run {
  std::vector<PlanResult> updates;
  std::vector<MachineSteps> axis_before;
};

// Drives the planner at 30 Hz from a virtual tool fed at 1 kHz: every update's limits and staircase
// are checked; the link completes each target before the next update.
Run drive(MachinePlanner& planner, const tables::PartTables& part, const std::vector<Eigen::Vector3d>& virtual_path,
          int extra_updates, const PlannerLimits& limits = sherline_limits()) {
  const MachineFrames frames = sherline_frames();
  const auto axis_budget = static_cast<std::int32_t>(
      std::floor(limits.speed.max_axis_speed_mm_per_s * limits.update_period_s * limits.speed.steps_per_mm));
  const auto total_budget = static_cast<std::int32_t>(std::floor(limits.speed.step_rate_steps_per_s * limits.update_period_s));
  Run run;
  const auto update = [&]() {
    const MachineSteps before = planner.axis_steps();
    const MachineSteps motor_before = planner.motor_steps();
    const PlanResult r = planner.plan(1);
    CHECK(r.status != PlanStatus::Fault);
    std::int32_t total = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const std::int32_t motor_move = std::abs(r.motor_target.axis[i] - motor_before.axis[i]);
      CHECK(motor_move <= axis_budget);
      total += motor_move;
    }
    CHECK(total <= total_budget);
    CHECK_EQUAL(total, r.motor_steps);
    if (r.status == PlanStatus::Moved && limits.path == MachinePath::Straight) {
      check_straight(part, frames, before, r.axis_target);
    } else if (r.status == PlanStatus::Moved) {
      check_staircase(part, frames, before, r.axis_target, r.order);
    } else {
      CHECK(r.axis_target == before);  // nothing but a move moves the tool
    }
    run.updates.push_back(r);
    run.axis_before.push_back(before);
  };
  for (std::size_t i = 0; i < virtual_path.size(); ++i) {
    CHECK(planner.follow(virtual_path[i]) != PathStatus::Full);
    if (i % 33 == 32) {
      update();
    }
  }
  for (int i = 0; i < extra_updates; ++i) {
    update();
  }
  return run;
}

// The virtual tool's path at the mill's speed from `from` through `waypoints`, remediated by the
// engine (so it hugs the part where a waypoint is inside it).
std::vector<Eigen::Vector3d> virtual_path(const tables::PartTables& part, const Eigen::Vector3d& from,
                                          const std::vector<Eigen::Vector3d>& waypoints, double speed_fraction,
                                          double standoff_mm = 0.0) {
  const MachineSpeed speed{1.4 * speed_fraction, 1000.0 * speed_fraction, 640.0};
  engine::StandoffPart view{};
  CHECK(engine::build_standoff_part(part, standoff_mm, view));
  engine::VirtualTool tool(view, from);
  tool.limit_speed(speed.max_axis_speed_mm_per_s * 0.001, speed.step_rate_steps_per_s / speed.steps_per_mm * 0.001);
  std::vector<Eigen::Vector3d> path;
  for (const Eigen::Vector3d& waypoint : waypoints) {
    // Long enough to get there at this speed, or to come to rest against the part.
    const int cycles = static_cast<int>((waypoint - tool.tip_mm()).cwiseAbs().sum() / (speed.max_axis_speed_mm_per_s * 0.001)) + 200;
    for (int cycle = 0; cycle < cycles; ++cycle) {
      const Eigen::Vector3d desired = limit_tool_move(speed, tool.tip_mm(), waypoint, 0.001);
      const engine::RemediationResult result = tool.step(desired, engine::ContactParameters{});
      CHECK(result.status != engine::RemediationStatus::Fault);
      path.push_back(tool.tip_mm());
      if ((tool.tip_mm() - waypoint).norm() < 1e-9) {
        break;
      }
    }
  }
  return path;
}

}  // namespace

TEST_GROUP(MachinePlanner){};

TEST(MachinePlanner, NothingIsCommandedBeforeHoming) {
  const Loaded loaded;
  MachinePlanner planner(loaded.part, sherline_frames(), sherline_limits());
  CHECK(planner.plan(0).status == PlanStatus::NotHomed);
}

TEST(MachinePlanner, FollowsAFreePathWithinTheMillsSpeedAndEndsExactlyOnIt) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  MachinePlanner planner(part, sherline_frames(), sherline_limits());
  planner.homed({{0, 0, 0}}, {1, 1, 1});
  const Eigen::Vector3d end = kHome + Eigen::Vector3d(1.2, -0.7, 0.9);  // +x, -y, +z: x and z need no take-up
  const std::vector<Eigen::Vector3d> path = virtual_path(part, kHome, {end}, 0.9);
  const Run run = drive(planner, part, path, 60);
  MachineSteps expected{};
  CHECK(world_to_steps(sherline_frames(), end, expected));
  CHECK(planner.axis_steps() == expected);
  CHECK(run.updates.back().status == PlanStatus::AtGoal);
  double worst_lag = 0.0;
  for (const PlanResult& r : run.updates) {
    worst_lag = std::max(worst_lag, r.lag_mm);
  }
  CHECK(worst_lag < 0.25);  // a few updates of motion at most
}

TEST(MachinePlanner, BacklashIsTakenUpOnEveryReversalSoTheToolIsWhereItWasCommanded) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  const PlannerLimits limits = sherline_limits();
  MachinePlanner planner(part, sherline_frames(), limits);
  planner.homed({{0, 0, 0}}, {-1, -1, -1});  // homed moving down: every slack on the minus side
  std::array<DeadbandAxis, 3> mill;
  for (std::size_t i = 0; i < 3; ++i) {
    mill[i].backlash = limits.backlash_steps[i];
    mill[i].motor = 0.0;  // the motor pushed the axis down to here: no gap below it
    mill[i].axis = 0.0;
  }
  const std::array<double, 3> axis_zero = {mill[0].axis, mill[1].axis, mill[2].axis};
  // Up, back down, up again on every axis: three reversals each after the first move.
  const std::vector<Eigen::Vector3d> corners = {kHome + Eigen::Vector3d(0.4, 0.3, 0.5), kHome,
                                                kHome + Eigen::Vector3d(-0.3, 0.2, 0.4),
                                                kHome + Eigen::Vector3d(0.2, -0.1, 0.1)};
  const std::vector<Eigen::Vector3d> path = virtual_path(part, kHome, corners, 0.9);
  int take_ups = 0;
  std::int32_t take_up_steps = 0;
  const MachineFrames frames = sherline_frames();
  for (std::size_t i = 0; i <= path.size() + 33 * 200; ++i) {
    if (i < path.size()) {
      CHECK(planner.follow(path[i]) != PathStatus::Full);
    }
    if (i % 33 != 32) {
      continue;
    }
    const PlanResult r = planner.plan(1);
    for (std::size_t a = 0; a < 3; ++a) {
      mill[a].move_motor_to(r.motor_target.axis[a]);
    }
    if (r.status == PlanStatus::TakingUp) {
      ++take_ups;
      take_up_steps += r.motor_steps;
    }
    // The true axis is exactly where the planner says the tool is, after every update.
    for (std::size_t a = 0; a < 3; ++a) {
      if (r.status != PlanStatus::TakingUp) {
        DOUBLES_EQUAL(static_cast<double>(r.axis_target.axis[a]), mill[a].axis - axis_zero[a], 0.0);
      }
    }
  }
  MachineSteps expected{};
  CHECK(world_to_steps(frames, corners.back(), expected));
  CHECK(planner.axis_steps() == expected);
  CHECK(take_ups > 0);
  // Reversals in machine steps (x and y count against the world), slack first on the minus side:
  // x world +,-,-,+ = steps -,+,+,- : 2; y world +,-,+,- = steps -,+,-,+ : 3; z +,-,+,- : 4.
  CHECK_EQUAL(2 * 80 + 3 * 32 + 4 * 80, take_up_steps);
}

TEST(MachinePlanner, AroundAConvexCornerOfTheHexPrismTheMillNeverCutsTheCornerAndKeepsUp) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  MachinePlanner planner(part, sherline_frames(), sherline_limits());
  // Start beside the prism's vertex at (33, 12.5), low enough that the cutter's side meets the
  // walls, then ask for points inside the prism on either side of the vertex: the virtual tool
  // slides along one wall, round the vertex, along the other.
  const Eigen::Vector3d start(33.0, 12.5 - 3.0, 2.0);
  const Eigen::Vector3d after(33.0 - 2.0, 12.5 + 4.0, 2.0);
  const MachineFrames frames = sherline_frames();
  MachineSteps start_steps{};
  CHECK(world_to_steps(frames, start, start_steps));
  CHECK(engine::check_tip_legal(part, steps_to_world(frames, start_steps)) == engine::Legality::Legal);
  planner.homed(start_steps, {1, 1, 1});
  const std::vector<Eigen::Vector3d> path =
      virtual_path(part, steps_to_world(frames, start_steps), {Eigen::Vector3d(31.5, 12.5, 2.0), after}, 0.8);
  // The straight way between the two sides goes through the prism: there is a corner to cut.
  const engine::SweepResult shortcut =
      engine::check_sweep(part, path.front(), path.back(), engine::sweep_step_mm(part), 100000);
  CHECK(shortcut.status == engine::SweepStatus::Illegal);
  const Run run = drive(planner, part, path, 200);
  // Every staircase was checked in drive(); the mill also got round.
  const Eigen::Vector3d reached = steps_to_world(frames, planner.axis_steps());
  CHECK((reached - path.back()).norm() < 0.01);
  int blocked = 0;
  int take_ups = 0;
  double worst_lag = 0.0;
  for (const PlanResult& r : run.updates) {
    blocked += r.status == PlanStatus::Blocked ? 1 : 0;
    take_ups += r.status == PlanStatus::TakingUp ? 1 : 0;
    worst_lag = std::max(worst_lag, r.lag_mm);
  }
  // The virtual tool trembles against the walls (tens of reversals, each a backlash take-up of up
  // to 2.4 updates), so the mill falls behind by a few tenths at worst and then catches up.
  CHECK(worst_lag < 0.5);
  CHECK(blocked < 20);
  std::printf("\n  hex prism corner, virtual tool at 80%% of the mill's speed: %zu updates, %d taking up backlash, "
              "%d blocked, worst lag %.3f mm\n",
              run.updates.size(), take_ups, blocked, worst_lag);
}

TEST(MachinePlanner, NeverCommandsBelowTheStockFloorOrOutsideTheTravelWhateverItIsHanded) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  MachinePlanner planner(part, sherline_frames(), sherline_limits());
  const Eigen::Vector3d corner(1.0, 1.0, 0.01);
  MachineSteps at{};
  CHECK(world_to_steps(sherline_frames(), corner, at));
  planner.homed(at, {-1, -1, -1});
  CHECK(planner.follow(corner + Eigen::Vector3d(-0.02, -0.02, -0.03)) == PathStatus::Added);
  for (int i = 0; i < 20; ++i) {
    // It may edge towards the point, but only as far as the floor and the travel allow.
    const PlanResult r = planner.plan(1);
    CHECK(r.status != PlanStatus::Fault);
    CHECK((steps_to_world(sherline_frames(), r.axis_target).array() >= 0.0).all());
  }
  CHECK(planner.path_size() == 1);  // never reached
  CHECK(planner.follow(Eigen::Vector3d(NAN, 1.0, 1.0)) == PathStatus::Invalid);
}

TEST(MachinePlanner, TheQueueHoldsAtMostTwoUpdates) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  MachinePlanner planner(part, sherline_frames(), sherline_limits());
  planner.homed({{0, 0, 0}}, {1, 1, 1});
  for (int i = 1; i <= 100; ++i) {
    CHECK(planner.follow(kHome + Eigen::Vector3d(0.0, 0.0, 0.002 * i)) == PathStatus::Added);
  }
  CHECK(planner.plan(0).status == PlanStatus::Moved);
  CHECK(planner.plan(0).status == PlanStatus::Moved);
  CHECK(planner.plan(0).status == PlanStatus::Waiting);
  CHECK_EQUAL(2, planner.queued());
  CHECK(planner.plan(1).status == PlanStatus::Moved);
}

// The standoff the rig keeps (0.015 mm) is more than the planner's argument needs: 5 steps per axis
// of 1/640 mm, sqrt(3) times over (13.5 um), with the virtual tool's 1 um a cycle; and one update's
// budget covers the fallback's move. A virtual tool faster than a step a cycle voids the argument.
TEST(MachinePlanner, TheStandoffTheArgumentNeedsIsUnderTheRigsAndTheFallbackFitsAnUpdate) {
  DOUBLES_EQUAL(std::sqrt(3.0) * 5.0 / 640.0, follow_standoff_needed_mm(640.0, 0.001), 1e-12);
  CHECK(follow_standoff_needed_mm(640.0, 0.001) < 0.015);
  CHECK(follow_standoff_needed_mm(640.0, 0.002) > 1.0);
  CHECK(follow_fallback_fits(sherline_limits()));
  PlannerLimits slow = sherline_limits();
  slow.speed.max_axis_speed_mm_per_s = 0.2;  // 4 steps an update: too few
  CHECK_FALSE(follow_fallback_fits(slow));
}

namespace {

// The virtual tool as the cycle moves it: the hand's point (the desired tip) walks through
// `waypoints` at 0.8 mm/s, deep into the part where they are, and the tool follows as far as it is
// legal, at most 1 um an axis a cycle (the rig's speed limit), keeping `standoff_mm` off the part.
std::vector<Eigen::Vector3d> pressed_path(const tables::PartTables& part, const Eigen::Vector3d& from,
                                          const std::vector<Eigen::Vector3d>& waypoints, double standoff_mm) {
  engine::StandoffPart view{};
  CHECK(engine::build_standoff_part(part, standoff_mm, view));
  engine::VirtualTool tool(view, from);
  tool.limit_speed(1e-3, 1e-3);
  std::vector<Eigen::Vector3d> path;
  Eigen::Vector3d hand = from;
  for (const Eigen::Vector3d& waypoint : waypoints) {
    while ((waypoint - hand).norm() > 1e-9) {
      const Eigen::Vector3d step = waypoint - hand;
      hand = step.norm() <= 0.8e-3 ? waypoint : Eigen::Vector3d(hand + 0.8e-3 * step.normalized());
      CHECK(tool.step(hand, engine::ContactParameters{}).status != engine::RemediationStatus::Fault);
      path.push_back(tool.tip_mm());
    }
  }
  for (int cycle = 0; cycle < 3000; ++cycle) {  // the hand rests where it ended: the tool settles
    static_cast<void>(tool.step(hand, engine::ContactParameters{}));
    path.push_back(tool.tip_mm());
  }
  return path;
}

// The pressed path for a standoff, made once per run: both following cases below press the same
// one (about 78,000 steps of the engine, most of this suite's time under the sanitizers: 30 s each).
// It outlives the case that makes it, so it is made with CppUTest's leak counting off and is never
// freed (still reachable, so not a leak to LeakSanitizer either).
const std::vector<Eigen::Vector3d>& pressed_path_once(const tables::PartTables& part, const Eigen::Vector3d& from,
                                                      const std::vector<Eigen::Vector3d>& waypoints,
                                                      double standoff_mm) {
  static std::vector<Eigen::Vector3d>* made = nullptr;
  static double made_for_mm = 0.0;
  if (made == nullptr || made_for_mm != standoff_mm) {
    MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
    delete made;
    made = new std::vector<Eigen::Vector3d>(pressed_path(part, from, waypoints, standoff_mm));
    made_for_mm = standoff_mm;
    MemoryLeakWarningPlugin::restoreNewDeleteOverloads();
  }
  return *made;
}

// A hand pressed hard into the prism: down onto the top and along it over the edge (where a job
// stalled: the tool rides the edge a micrometre off it), round a vertex low on the walls, and down
// into the concave corner of a wall and the floor from several directions; the mill follows at
// 30 Hz (every staircase checked in drive()). Returns the updates that found no way.
int blocked_following_a_pressed_tool(double standoff_mm, const PlannerLimits& limits = sherline_limits()) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  MachinePlanner planner(part, sherline_frames(), limits);
  const MachineFrames frames = sherline_frames();
  const Eigen::Vector3d start(17.7, 9.8, 7.0);
  MachineSteps start_steps{};
  CHECK(world_to_steps(frames, start, start_steps));
  planner.homed(start_steps, {1, 1, 1});
  const std::vector<Eigen::Vector3d> waypoints = {
      {18.76, 12.16, 0.18}, {18.69, 12.39, 0.1}, {21.33, 9.46, 0.34}, {22.0, 8.69, 0.63},  {23.36, 7.05, 2.69},
      {33.0, 9.5, 8.0},     {33.0, 9.5, 2.0},    {31.5, 12.5, 2.0},   {31.0, 16.5, 1.0},   {31.0, 15.5, -1.0},
      {32.0, 14.0, -2.0},   {30.5, 17.0, -1.5},  {31.5, 13.0, -0.5},  {31.0, 16.0, -3.0},  {29.0, 18.0, -1.0}};
  const std::vector<Eigen::Vector3d>& path =
      pressed_path_once(part, steps_to_world(frames, start_steps), waypoints, standoff_mm);
  const Run run = drive(planner, part, path, 300, limits);
  int blocked = 0;
  for (const PlanResult& r : run.updates) {
    blocked += r.status == PlanStatus::Blocked ? 1 : 0;
  }
  const Eigen::Vector3d reached = steps_to_world(frames, planner.axis_steps());
  std::printf("\n  pressed over the prism's edge, round a vertex and into its corner with the floor, standoff "
              "%.3f mm, %s: %zu updates, %d blocked, the mill ends %.4f mm from the virtual tool\n",
              standoff_mm, limits.path == MachinePath::Straight ? "straight segments" : "staircases",
              run.updates.size(), blocked, (reached - path.back()).norm());
  return blocked;
}

}  // namespace

// With the rig's standoff the mill always has a way: not one update blocked, whatever the hand does.
TEST(MachinePlanner, WithTheStandoffTheMillFollowsAToolPressedIntoTheFloorsCornerFromEveryDirection) {
  CHECK_EQUAL(0, blocked_following_a_pressed_tool(0.015));
}


// A mill that moves in straight segments (LinuxCNC) gets each segment checked, not a staircase:
// pressed the same way, every segment is legal at 2 um (drive() checks it) and none blocks.
TEST(MachinePlanner, StraightSegmentsAreCheckedAsTheMillMovesThemAndTheMillFollowsAPressedTool) {
  CHECK_EQUAL(0, blocked_following_a_pressed_tool(0.015, straight_limits()));
}

// Beside the prism's vertex, a target one update away whose straight segment cuts the vertex: the
// straight mill does not go there, while a staircase mill goes round the vertex. (A one-second update,
// so that the way round is in reach: within a 30 Hz update's 0.045 mm a chord of the tool's path
// round the vertex strays into the part by far less than the tables' tolerance.)
TEST(MachinePlanner, AStraightSegmentThatCutsTheCornerIsNotTaken) {
  const Loaded loaded;
  const tables::PartTables& part = loaded.part;
  const MachineFrames frames = sherline_frames();
  // The vertex of the prism at (33, 12.5): the tool's side against both walls, 2 mm up.
  const std::vector<Eigen::Vector3d> around =
      virtual_path(part, Eigen::Vector3d(33.0, 9.5, 2.0), {Eigen::Vector3d(31.5, 12.5, 2.0), Eigen::Vector3d(31.0, 16.5, 2.0)}, 0.8);
  bool found = false;
  MachineSteps from{};
  MachineSteps to{};
  for (std::size_t i = 0; i < around.size() && !found; i += 50) {
    for (std::size_t j = i + 50; j < around.size() && !found; j += 50) {
      MachineSteps a{};
      MachineSteps b{};
      CHECK(world_to_steps(frames, around[i], a));
      CHECK(world_to_steps(frames, around[j], b));
      bool fits = true;
      for (std::size_t k = 0; k < 3; ++k) {
        fits = fits && std::abs(b.axis[k] - a.axis[k]) <= 800;
      }
      if (!fits) {
        break;
      }
      const Eigen::Vector3d wa = steps_to_world(frames, a);
      const Eigen::Vector3d wb = steps_to_world(frames, b);
      if (engine::check_tip_legal(part, wa) != engine::Legality::Legal ||
          engine::check_tip_legal(part, wb) != engine::Legality::Legal) {
        continue;
      }
      const auto legal = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
        return engine::check_sweep(part, p, q, engine::sweep_step_mm(part), 100000).status == engine::SweepStatus::Legal;
      };
      const Eigen::Vector3d x_first(wb.x(), wa.y(), wa.z());
      const Eigen::Vector3d y_first(wa.x(), wb.y(), wa.z());
      const bool round_it = (legal(wa, x_first) && legal(x_first, wb)) || (legal(wa, y_first) && legal(y_first, wb));
      if (!legal(wa, wb) && round_it && wa.z() == wb.z()) {
        from = a;
        to = b;
        found = true;
      }
    }
  }
  CHECK_TEXT(found, "no chord across the vertex within one update: the test's set-up is wrong");
  const auto plan_to = [&](const PlannerLimits& limits) {
    MachinePlanner planner(part, frames, limits);
    planner.homed(from, {1, 1, 1});
    CHECK(planner.follow(steps_to_world(frames, to)) == PathStatus::Added);
    return planner.plan(0);
  };
  PlannerLimits staircase = sherline_limits();
  staircase.backlash_steps = {0, 0, 0};
  staircase.update_period_s = 1.0;
  PlannerLimits straight = straight_limits();
  straight.update_period_s = 1.0;
  const PlanResult by_staircase = plan_to(staircase);
  const PlanResult by_segment = plan_to(straight);
  CHECK(by_staircase.status == PlanStatus::Moved);
  CHECK(by_staircase.axis_target == to);
  check_staircase(part, frames, from, to, by_staircase.order);
  CHECK_FALSE(by_segment.status == PlanStatus::Moved && by_segment.axis_target == to);
  if (by_segment.status == PlanStatus::Moved) {
    check_straight(part, frames, from, by_segment.axis_target);
  }
}
