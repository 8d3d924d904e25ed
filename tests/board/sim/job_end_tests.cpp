// When a simulated job ends (board/sim/job_end): at its script's end or its --duration once the mill
// has caught up, or at most 30 s later whatever the mill does; a replay ends with its records only;
// --until-complete ends once every reachable triangle is touched and the mill has caught up; the
// progress line every 10 simulated seconds. Against a real controller over the hex prism's tables.
#include <memory>
#include <utility>
#include <vector>

#include "board/sim/job_end.hpp"
#include "board/sim/sim_job.hpp"
#include "firmware/core/control/controller.hpp"
#include "tests/fakes/fake_haptic_device.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

// A controller that has run no cycle: nothing touched.
struct Bench {
  test::LoadedPart loaded{test::default_part(), 1};
  test::FakeHapticDevice device;
  std::unique_ptr<control::CycleRingStorage> rings = std::make_unique<control::CycleRingStorage>();
  std::unique_ptr<control::Controller> controller =
      std::make_unique<control::Controller>(loaded.part, device, rings->rings(), controller_config(false));
  SimJob job;
  Bench() {
    job.part = &loaded.part;
    job.script.t_s = {0.0, 20.0};
    job.script.device_mm = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    job.script.angles_rad = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  }
};

}  // namespace

TEST_GROUP(JobEnd){};

TEST(JobEnd, EndsAtTheScriptsEndOnceTheMillHasCaughtUp) {
  Bench b;
  JobEnd end(b.job, *b.controller);
  CHECK_FALSE(end.job_done(19.9, true));
  CHECK_FALSE(end.job_done(20.0, false));
  CHECK_TRUE(end.job_done(20.0, true));
  CHECK_FALSE(end.complete());
}

TEST(JobEnd, GivesTheMill30SecondsToCatchUpThenEndsAnyway) {
  Bench b;
  JobEnd end(b.job, *b.controller);
  CHECK_FALSE(end.job_done(49.9, false));
  CHECK_TRUE(end.job_done(50.0, false));
}

TEST(JobEnd, ADurationGivenOverridesTheScripts) {
  Bench b;
  b.job.duration_s = 5.0;
  JobEnd end(b.job, *b.controller);
  CHECK_FALSE(end.job_done(4.0, true));
  CHECK_TRUE(end.job_done(5.0, true));
}

TEST(JobEnd, AReplayEndsOnlyWithItsRecords) {
  Bench b;
  const std::vector<journal::RecordedCycle> recorded;
  b.job.replay = &recorded;
  b.job.duration_s = 5.0;
  JobEnd end(b.job, *b.controller);
  CHECK_FALSE(end.job_done(1e6, true));
}

TEST(JobEnd, UntilCompleteEndsOnceEveryReachableTriangleIsTouchedAndTheMillCaughtUp) {
  Bench b;
  b.job.until_complete = true;
  {
    JobEnd end(b.job, *b.controller);
    CHECK_FALSE(end.job_done(1.0, true));  // nothing touched yet
    CHECK_FALSE(end.complete());
  }
  // A part with no reachable triangle is covered from the start.
  tables::PartTables nothing_reachable = b.loaded.part;
  nothing_reachable.header.reachable_triangle_count = 0;
  b.job.part = &nothing_reachable;
  JobEnd end(b.job, *b.controller);
  CHECK_FALSE(end.job_done(1.0, false));
  CHECK_TRUE(end.job_done(1.0, true));
  CHECK_TRUE(end.complete());
}

TEST(JobEnd, TellsTheProgressEveryTenSimulatedSeconds) {
  Bench b;
  std::vector<std::pair<double, double>> told;
  b.job.progress = [&told](double t_s, double coverage) { told.emplace_back(t_s, coverage); };
  JobEnd end(b.job, *b.controller);
  for (double t = 0.0; t <= 25.0; t += 0.5) {
    static_cast<void>(end.job_done(t, false));
  }
  CHECK_EQUAL(2U, told.size());
  DOUBLES_EQUAL(10.0, told[0].first, 0.0);
  DOUBLES_EQUAL(20.0, told[1].first, 0.0);
  DOUBLES_EQUAL(0.0, told[0].second, 0.0);
}
