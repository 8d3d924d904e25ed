// What the operator feels (stencil/haptic_force.hpp): the coupling to the virtual tool in device
// millimetres plus the contact force, each of force and torque clamped in magnitude (5 N, 200 N mm
// on the rig), and zero with the fault flag for anything not finite or a query that failed.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "firmware/core/stencil/haptic_force.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::engine;

namespace {

const double kNan = std::numeric_limits<double>::quiet_NaN();

ContactResult contact(const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nmm,
                      QueryStatus status = QueryStatus::Ok) {
  return {status, 1, 0.01, 0, force_n, torque_nmm};
}

const ContactResult kNoContact = contact(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());

}  // namespace

TEST_GROUP(HapticOutput){};

TEST(HapticOutput, CouplingPullsTowardsTheVirtualToolAndIsClampedAtFiveNewtons) {
  const HapticLimits limits{};
  const HapticOutput small = haptic_output({0, 0, 0}, {0.1, 0, 0}, kNoContact, limits);
  CHECK((small.force_n - Eigen::Vector3d(0.5, 0, 0)).norm() < 1e-12);  // 0.5 N/mm x 1 device mm
  CHECK_FALSE(small.clamped);
  const HapticOutput large = haptic_output({0, 0, 0}, {0, 3.0, 0}, kNoContact, limits);
  DOUBLES_EQUAL(5.0, large.force_n.norm(), 1e-12);
  CHECK(large.clamped);
  CHECK(large.force_n.normalized().dot(Eigen::Vector3d::UnitY()) > 0.999999);
}

TEST(HapticOutput, TheContactForceAddsToTheCouplingBeforeTheClamp) {
  const HapticLimits limits{};
  // 0.5 N/mm x 10 device mm/world mm x 0.2 world mm = 1 N along +x, plus 2 N of contact along +z.
  const HapticOutput sum = haptic_output({0, 0, 0}, {0.2, 0, 0}, contact({0, 0, 2.0}, {1.0, 0, 0}), limits);
  CHECK((sum.force_n - Eigen::Vector3d(1.0, 0, 2.0)).norm() < 1e-12);
  CHECK(sum.torque_nmm == Eigen::Vector3d(1.0, 0, 0));
  CHECK_FALSE(sum.clamped);
  CHECK_FALSE(sum.fault);
  // A contact force that cancels the coupling leaves nothing; one that adds to it is clamped as one.
  CHECK(haptic_output({0, 0, 0}, {0.2, 0, 0}, contact({-1.0, 0, 0}, {0, 0, 0}), limits).force_n.norm() < 1e-12);
  const HapticOutput both = haptic_output({0, 0, 0}, {0.6, 0, 0}, contact({4.0, 0, 0}, {0, 0, 0}), limits);
  CHECK((both.force_n - Eigen::Vector3d(5.0, 0, 0)).norm() < 1e-12);
  CHECK(both.clamped);
}

TEST(HapticOutput, TheTorqueIsClampedOnItsOwnAndTheForceLimitIsTheBoardsNumber) {
  HapticLimits limits{};
  limits.max_force_n = 2.0;
  limits.max_torque_nmm = 50.0;
  const HapticOutput out = haptic_output({0, 0, 0}, {0, 0, 0}, contact({0, 1.0, 0}, {0, 300.0, 400.0}), limits);
  CHECK((out.force_n - Eigen::Vector3d(0, 1.0, 0)).norm() < 1e-12);  // under its limit: untouched
  CHECK((out.torque_nmm - Eigen::Vector3d(0, 30.0, 40.0)).norm() < 1e-12);  // 500 down to 50, same way
  CHECK(out.clamped);
  DOUBLES_EQUAL(2.0, haptic_output({0, 0, 0}, {0, 0, -1.0}, kNoContact, limits).force_n.norm(), 1e-12);
  // Exactly at the limit is not clamped.
  CHECK_FALSE(haptic_output({0, 0, 0}, {0, 0, 0}, contact({0, 0, 2.0}, {0, 0, 0}), limits).clamped);
}

TEST(HapticOutput, ANonFiniteInputGivesZeroAndAFault) {
  const ContactResult bad_force = contact(Eigen::Vector3d(0, 0, kNan), Eigen::Vector3d::Zero());
  const HapticOutput out = haptic_output({0, 0, 0}, {0, 0, 0}, bad_force, HapticLimits{});
  CHECK(out.fault);
  CHECK(out.force_n == Eigen::Vector3d::Zero());
  CHECK(haptic_output({kNan, 0, 0}, {0, 0, 0}, kNoContact, HapticLimits{}).fault);
  CHECK(haptic_output({0, 0, 0}, {0, kNan, 0}, kNoContact, HapticLimits{}).fault);
  CHECK(haptic_output({0, 0, 0}, {0, 0, 0}, contact({0, 0, 0}, {kNan, 0, 0}), HapticLimits{}).fault);
  HapticLimits bad_limit{};
  bad_limit.max_force_n = std::numeric_limits<double>::infinity();  // no clamp is no safety
  const HapticOutput unlimited = haptic_output({0, 0, 0}, {1.0, 0, 0}, kNoContact, bad_limit);
  CHECK(unlimited.fault);
  CHECK(unlimited.force_n == Eigen::Vector3d::Zero());
}

TEST(HapticOutput, AQueryThatFailedGivesZeroAndAFaultWhateverItsNumbers) {
  for (const QueryStatus status : {QueryStatus::BadInput, QueryStatus::BadTree}) {
    const HapticOutput out = haptic_output({0, 0, 0}, {0.1, 0, 0}, contact({1.0, 0, 0}, {0, 0, 0}, status), HapticLimits{});
    CHECK(out.fault);
    CHECK(out.force_n == Eigen::Vector3d::Zero());
    CHECK(out.torque_nmm == Eigen::Vector3d::Zero());
    CHECK_FALSE(out.clamped);
  }
}
