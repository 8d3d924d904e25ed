// The machine side end to end, on wall time: the engine's virtual tool slides round a vertex of the
// hex prism at 80% of the mill's speed; the planner turns its path into updates; the CY545 driver
// sends them over a real pseudo-terminal to the simulated CY545, which steps the simulated mill
// (with its backlash). At the end the mill's true axes stand exactly where the planner put them,
// and no position the mill reached on the way was illegal.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/sim_facts.hpp"
#include "firmware/core/motion/machine_planner.hpp"
#include "firmware/core/motion/speed_limit.hpp"
#include "firmware/core/stencil/sweep.hpp"
#include "firmware/core/stencil/virtual_tool.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_runner.hpp"
#include "sim/mill/simulated_mill.hpp"
#include "tests/support/gouge_oracle.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace rig = stencil::board::sherline_suzuki;
using stencil::sim::Axis;
using stencil::sim::StepDirection;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

}  // namespace

TEST_GROUP(MillChain){};

TEST(MillChain, TheMillFollowsTheVirtualToolRoundTheHexPrismThroughTheRealDriverAndEndsExactlyThere) {
  const tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);

  // The machine homes with the tool beside the prism's vertex at (33, 12.5), low enough for the
  // cutter's side to meet the walls.
  const Eigen::Vector3d home(33.0, 9.5, 2.0);
  const motion::MachineFrames frames{rig::kRig.haptic_to_machine_scale, Eigen::Vector3d::Zero(), home, {-1, -1, 1},
                                     rig::kRig.steps_per_mm};
  const motion::PlannerLimits limits = rig::kPlannerLimits;

  sim::SimulatedMill mill{board::sim::kMillConfig};
  mill.place_axis(Axis::x, 150, StepDirection::positive);
  mill.place_axis(Axis::y, 60, StepDirection::positive);
  mill.place_axis(Axis::z, 190, StepDirection::positive);
  sim::cy545::FakeCy545 fake{mill, board::sim::kMmc4sWiring, hal::posix_clock::monotonic_now_ns()};
  hal::posix_clock::MonotonicClock clock;
  hal::cy545::SerialPort port;
  char error[256] = {};
  CHECK_TEXT(port.open(fake.slave_path().c_str(), rig::kRig.serial_baud, error), error);
  hal::cy545::Cy545Config config = rig::kCy545;
  config.motion.homing_rate = 20000;
  config.motion.homing_slow_rate = 5000;
  config.reply_timeout_ns = 1000 * kMs;  // the fake is a thread on a host that is not real-time (and CI's sanitizers)
  config.motion.homing_travel_steps = 2000;
  hal::cy545::Cy545Link link(port, clock, config);
  sim::cy545::FakeCy545Runner runner{fake};
  CHECK_TEXT(link.start(clock.now_ns() + 2000 * kMs).done, link.last_error());
  CHECK_TEXT(link.home(clock.now_ns() + link.homing_bound_ns() + 1000 * kMs).done, link.last_error());
  CHECK(link.set_spindle(true, clock.now_ns() + 200 * kMs).done);
  const std::array<std::int64_t, 3> axis_at_home = runner.with_fake([&](sim::cy545::FakeCy545&) {
    return std::array<std::int64_t, 3>{mill.axis_position_steps(Axis::x), mill.axis_position_steps(Axis::y),
                                       mill.axis_position_steps(Axis::z)};
  });

  motion::MachinePlanner planner(part, frames, limits);
  planner.homed({{0, 0, 0}}, link.home_approach());

  // The virtual tool at 80% of the mill's speed, pushed into the prism beside the vertex and then
  // past it: it slides along one wall and round the corner.
  engine::VirtualTool tool(part, home);
  tool.limit_speed(0.8 * 1.4 * 0.001, 0.8 * 1000.0 / 640.0 * 0.001);
  std::vector<Eigen::Vector3d> desired;
  for (int i = 0; i < 2200; ++i) {
    desired.push_back(i < 1400 ? Eigen::Vector3d(31.5, 12.5, 2.0) : Eigen::Vector3d(31.8, 14.0, 2.0));
  }
  double worst_lag = 0.0;
  int updates = 0;
  int take_ups = 0;
  const std::uint64_t bytes_before = link.status().bytes_sent;
  const auto begin = std::chrono::steady_clock::now();
  const auto machine_update = [&]() {
    const motion::PlanResult plan = planner.plan(1);  // the driver's moves are done when it returns
    CHECK(plan.status != motion::PlanStatus::Fault);
    worst_lag = std::max(worst_lag, plan.lag_mm);
    if (plan.status != motion::PlanStatus::Moved && plan.status != motion::PlanStatus::TakingUp) {
      return;
    }
    ++updates;
    take_ups += plan.status == motion::PlanStatus::TakingUp ? 1 : 0;
    const hal::MachineResult moved =
        link.move({plan.motor_target.axis, plan.order, true}, clock.now_ns() + 500 * kMs);
    CHECK_TEXT(moved.done, link.last_error());
    // Where the mill's tool truly is (its axes, after the screws' play): legal, and no gouge.
    const std::array<std::int64_t, 3> axis = runner.with_fake([&](sim::cy545::FakeCy545&) {
      return std::array<std::int64_t, 3>{mill.axis_position_steps(Axis::x), mill.axis_position_steps(Axis::y),
                                         mill.axis_position_steps(Axis::z)};
    });
    const motion::MachineSteps truth{{static_cast<std::int32_t>(axis[0] - axis_at_home[0]),
                                      static_cast<std::int32_t>(axis[1] - axis_at_home[1]),
                                      static_cast<std::int32_t>(axis[2] - axis_at_home[2])}};
    const Eigen::Vector3d at = motion::steps_to_world(frames, truth);
    CHECK(engine::check_tip_legal(part, at) == engine::Legality::Legal);
    CHECK(test::ball_end_gouge_mm(part, at) <= part.header.gouge_bound_mm + 1e-5);
    if (plan.status == motion::PlanStatus::Moved) {
      CHECK(truth == plan.axis_target);  // backlash taken up: the tool is where it was sent
    }
  };
  const motion::MachineSpeed operator_speed{0.8 * 1.4, 0.8 * 1000.0, 640.0};
  for (std::size_t i = 0; i < desired.size(); ++i) {
    // The operator's hand moves at the same pace (a desired pose far inside the part would leave the
    // virtual tool stuck where it is, which is right but shows nothing here).
    const Eigen::Vector3d step = motion::limit_tool_move(operator_speed, tool.tip_mm(), desired[i], 0.001);
    static_cast<void>(tool.step(step, engine::ContactParameters{}));
    CHECK(planner.follow(tool.tip_mm()) != motion::PathStatus::Full);
    if (i % 33 == 32) {
      machine_update();
    }
  }
  for (int i = 0; i < 100 && planner.path_size() > 0; ++i) {
    machine_update();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  CHECK_TEXT(link.verify(clock.now_ns() + 200 * kMs).done, link.last_error());
  const Eigen::Vector3d reached = motion::steps_to_world(frames, planner.axis_steps());
  // Within a step of the virtual tool on each axis, or within the reversal deadband (and a step of
  // rounding) where the planner held an axis rather than take up backlash for a tremor.
  const double held_mm = (motion::kReversalDeadbandSteps + 1.0) / frames.steps_per_mm;
  CHECK(((reached - tool.tip_mm()).cwiseAbs().array() <= held_mm).all());
  CHECK(worst_lag < 0.5);
  std::printf("\n  mill chain round the prism's vertex: %d updates (%d taking up backlash) in %.1f s = %.1f updates/s, "
              "%.1f bytes/update, worst lag %.3f mm\n",
              updates, take_ups, seconds, updates / seconds,
              static_cast<double>(link.status().bytes_sent - bytes_before) / std::max(1, updates), worst_lag);
}
