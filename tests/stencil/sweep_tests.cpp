// The checked straight move (stencil/sweep.hpp) on the hex prism (circumradius 8 mm, height 6 mm,
// centred at (25, 12.5), a corner towards +x) with the default 3 mm ball end mill: where a tip is
// legal, and a sweep's sub-steps, its stop before the part, its step limit and its refusals.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/sweep.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::engine;

namespace {

constexpr double kTop_mm = 6.0;
constexpr double kCornerX_mm = 25.0 + 8.0;  // the corner towards +x, on y = 12.5
constexpr double kToolRadius_mm = 1.5;
const double kNan = std::numeric_limits<double>::quiet_NaN();

}  // namespace

TEST_GROUP(Sweep) {
  const test::LoadedPart prism{test::default_part()};
  const tables::PartTables& part = prism.part;
  void setup() override { CHECK(prism.loaded); }
};

TEST(Sweep, ATipIsLegalAboveThePartAndInsideTheWorkspaceOnly) {
  CHECK(check_tip_legal(part, {25.0, 12.5, kTop_mm + 0.1}) == Legality::Legal);
  CHECK(check_tip_legal(part, {25.0, 12.5, kTop_mm - 0.1}) == Legality::Illegal);  // in the part
  CHECK(check_tip_legal(part, {5.0, 5.0, 0.0}) == Legality::Legal);                // on the stock floor
  CHECK(check_tip_legal(part, {5.0, 5.0, -0.001}) == Legality::Illegal);           // under it
  CHECK(check_tip_legal(part, {-0.001, 5.0, 10.0}) == Legality::Illegal);
  const double far_x = part.header.workspace_mm[0];
  CHECK(check_tip_legal(part, {far_x, 5.0, 10.0}) == Legality::Legal);  // the box is closed
  CHECK(check_tip_legal(part, {far_x + 0.001, 5.0, 10.0}) == Legality::Illegal);
  CHECK(check_tip_legal(part, {5.0, kNan, 10.0}) == Legality::Fault);
}

TEST(Sweep, TheSubStepIsHalfTheTablesSpacing) {
  DOUBLES_EQUAL(0.5 * part.header.covering_radius_mm, sweep_step_mm(part), 0.0);
  CHECK(sweep_step_mm(part) > 0.0);
}

TEST(Sweep, AFreeMoveIsCheckedInEqualSubStepsAndEndsExactlyOnItsTarget) {
  const Eigen::Vector3d from(5.0, 5.0, 10.0);
  const Eigen::Vector3d to(5.375, 5.5, 10.0);  // 0.625 mm: five sub-steps of 0.125, all exact
  const SweepResult r = check_sweep(part, from, to, 0.125, 100);
  CHECK(r.status == SweepStatus::Legal);
  CHECK(r.reached_mm == to);
  CHECK(r.blocked_mm == to);
  LONGS_EQUAL(5, r.steps);
  const SweepResult still = check_sweep(part, from, from, 0.1, 100);
  CHECK(still.status == SweepStatus::Legal);
  LONGS_EQUAL(0, still.steps);
  CHECK(still.reached_mm == from);
}

TEST(Sweep, AMoveIntoThePartStopsAtTheLastLegalSubStepBeforeIt) {
  // Along y = 12.5 from the left, at mid-height: the tool's side meets the corner towards -x.
  const Eigen::Vector3d from(5.0, 12.5, 3.0);
  const Eigen::Vector3d to(45.0, 12.5, 3.0);
  const double step = sweep_step_mm(part);
  const SweepResult r = check_sweep(part, from, to, step, 1'000'000);
  CHECK(r.status == SweepStatus::Illegal);
  CHECK(check_tip_legal(part, r.reached_mm) == Legality::Legal);
  CHECK(check_tip_legal(part, r.blocked_mm) == Legality::Illegal);
  DOUBLES_EQUAL(step, (r.blocked_mm - r.reached_mm).norm(), 1e-9);  // consecutive sub-steps
  const double contact_x = 25.0 - 8.0 - kToolRadius_mm;
  CHECK(r.reached_mm.x() <= contact_x + part.header.gouge_bound_mm);
  CHECK(r.reached_mm.x() > contact_x - 2.0 * step - part.header.gouge_bound_mm);
  DOUBLES_EQUAL(12.5, r.reached_mm.y(), 1e-12);  // the direction kept
  CHECK(r.blocked_mm.x() < kCornerX_mm);
}

TEST(Sweep, ALongMoveStopsAfterItsStepLimitAllLegal) {
  const Eigen::Vector3d from(5.0, 5.0, 10.0);
  const SweepResult r = check_sweep(part, from, Eigen::Vector3d(15.0, 5.0, 10.0), 0.125, 7);
  CHECK(r.status == SweepStatus::Limited);
  LONGS_EQUAL(7, r.steps);
  CHECK((r.reached_mm - Eigen::Vector3d(5.875, 5.0, 10.0)).norm() < 1e-12);  // seven full sub-steps
  // Exactly as many sub-steps as the limit still reaches the target, the last one shorter.
  const Eigen::Vector3d near(5.3, 5.0, 10.0);  // 2.4 sub-steps: three
  const SweepResult exact = check_sweep(part, from, near, 0.125, 3);
  CHECK(exact.status == SweepStatus::Legal);
  LONGS_EQUAL(3, exact.steps);
  CHECK(exact.reached_mm == near);
}

TEST(Sweep, BadInputIsAFaultWithNothingChecked) {
  const Eigen::Vector3d from(5.0, 5.0, 10.0);
  const Eigen::Vector3d to(6.0, 5.0, 10.0);
  CHECK(check_sweep(part, from, to, 0.0, 10).status == SweepStatus::Fault);
  CHECK(check_sweep(part, from, to, kNan, 10).status == SweepStatus::Fault);
  CHECK(check_sweep(part, from, to, 0.1, 0).status == SweepStatus::Fault);
  const SweepResult nan_target = check_sweep(part, from, Eigen::Vector3d(kNan, 5.0, 10.0), 0.1, 10);
  CHECK(nan_target.status == SweepStatus::Fault);
  LONGS_EQUAL(0, nan_target.steps);
  CHECK(nan_target.reached_mm == from);
  // A sub-step outside the workspace is illegal, not a fault: the floor stops a plunge.
  CHECK(check_sweep(part, from, Eigen::Vector3d(5.0, 5.0, -1.0), 0.1, 1000).status == SweepStatus::Illegal);
}
