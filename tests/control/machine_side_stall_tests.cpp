// The machine side when the mill finds no legal way (issue 20): the virtual tool is held (the
// backlog reported at 100 %) from the first such update, the job goes on while it lasts less than
// 3 s, and past that it is a fault that says where the virtual tool and the mill were and what the
// planner tried. A path point inside the part stands in for a premise broken (with the standoff the
// cycle never hands one over).
#include <cstdint>
#include <memory>

#include "firmware/core/control/machine_side.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "tests/fakes/spy_machine_link.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

constexpr hal::MonotonicNs kUpdateNs = 33'333'333;

struct Bench {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  control::MachineHandoffRing handoffs;
  control::MachineEventRing events;
  test::SpyMachineLink link;
  // Home above the hex prism (its top is at z 6, its centre at x 25, y 12.5).
  motion::MachineFrames frames{10.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(25.0, 12.5, 7.0), {-1, -1, -1}, 640.0};
  motion::PlannerLimits limits{{1.4, 1000.0, 640.0}, 1.0 / 30.0, {80, 32, 80}};
  std::unique_ptr<control::MachineSide> machine;
  hal::MonotonicNs now = 0;
  std::uint64_t cycle = 0;

  Bench() {
    CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok);
    machine = std::make_unique<control::MachineSide>(part, link, frames, limits, handoffs, events);
    CHECK_TRUE(machine->start(1'000'000'000));
  }
  // One update's cycles handing over `tip`, then the update; the backlog it reports (-1: none).
  int update(const Eigen::Vector3d& tip) {
    for (int i = 0; i < 33; ++i) {
      CHECK(handoffs.push({++cycle, {tip.x(), tip.y(), tip.z()}, false, false}));
    }
    now += kUpdateNs;
    machine->update(now + 2 * kUpdateNs);
    int backlog = -1;
    control::MachineEvent event{};
    while (events.pop(event)) {
      backlog = event.kind == control::MachineEventKind::Backlog ? event.backlog_percent : backlog;
      faults += event.kind == control::MachineEventKind::Fault ? 1 : 0;
    }
    return backlog;
  }
  int faults = 0;
};

}  // namespace

TEST_GROUP(MachineSideStall){};

TEST(MachineSideStall, AMillWithNoWayHoldsTheVirtualToolAndAfterThreeSecondsStopsSayingWhere) {
  Bench bench;
  const Eigen::Vector3d free(25.0, 12.5, 6.02);
  const Eigen::Vector3d inside(25.0, 12.5, 5.99);  // the tip under the prism's top: no staircase reaches it
  for (int i = 0; i < 40; ++i) {
    CHECK(bench.update(free) < 100);  // down from home to just over the top
  }
  // The first update with no way holds; from the next one on the cycle hears 100 %.
  static_cast<void>(bench.update(inside));
  for (int i = 0; i < 60; ++i) {
    CHECK_EQUAL(100, bench.update(inside));
  }
  CHECK_FALSE(bench.machine->stalled());
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);  // 2 s: the job goes on
  CHECK_EQUAL(0, bench.faults);
  for (int i = 0; i < 40 && !bench.machine->stalled(); ++i) {
    static_cast<void>(bench.update(inside));
  }
  CHECK_TRUE(bench.machine->stalled());
  CHECK(bench.machine->state() == control::MachineSideState::Stopped);
  CHECK_EQUAL(1, bench.faults);
  const control::MachineSide::Stall& stall = bench.machine->stall();
  CHECK((stall.virtual_tip_mm - inside).norm() < 1e-12);
  CHECK((stall.mill_tip_mm - free).norm() < 0.01);  // it got as far as the last free point
  CHECK((stall.search.next_point_mm - inside).norm() < 1e-12);
  CHECK(stall.search.candidates >= 1);
  CHECK(stall.search.corners >= 1);
  CHECK_EQUAL(0, stall.search.legal_corners);  // every corner of that cell is in the part
}

// A mill that finds its way again before 3 s is no fault: once the path goes on to points it can
// reach (the farthest reachable point is tried first), the hold ends and the job goes on.
TEST(MachineSideStall, AWayFoundAgainBeforeThreeSecondsEndsTheHoldWithNoFault) {
  Bench bench;
  const Eigen::Vector3d free(25.0, 12.5, 6.02);
  const Eigen::Vector3d inside(25.0, 12.5, 5.99);
  for (int i = 0; i < 40; ++i) {
    CHECK(bench.update(free) < 100);
  }
  for (int i = 0; i < 60; ++i) {
    static_cast<void>(bench.update(inside));
  }
  CHECK_EQUAL(100, bench.update(inside));
  const std::size_t moves = bench.link.moves().size();
  CHECK(bench.update(free + Eigen::Vector3d(0.01, 0.0, 0.0)) == 100);  // the update that finds the way
  CHECK(bench.link.moves().size() > moves);
  CHECK(bench.update(free + Eigen::Vector3d(0.02, 0.0, 0.0)) < 100);
  for (int i = 0; i < 100; ++i) {
    static_cast<void>(bench.update(free + Eigen::Vector3d(0.02, 0.0, 0.0)));
  }
  CHECK_FALSE(bench.machine->stalled());
  CHECK(bench.machine->state() == control::MachineSideState::Cutting);
  CHECK_EQUAL(0, bench.faults);
}
