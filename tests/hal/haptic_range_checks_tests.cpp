// The haptic range rules as functions (hal/haptic_range_checks.hpp), alone: which samples are refused
// (not finite, beyond the reach around its centre, angles beyond their limit; the edges accepted),
// how a command is clamped (magnitude scaled down, direction kept, force and torque apart, a non-finite
// command zeroed), how a write's outcome is counted, and the rounding toward zero onto the wire.
#include <cmath>
#include <cstdint>
#include <limits>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/haptic_range_checks.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using hal::WriteStatus;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A small reach around (10, 20, 30): 1, 2, 3 mm either side, angles to 0.5 rad.
constexpr hal::HapticRange kSmallRange{{1.0, 2.0, 3.0}, 0.5, 5.0, 200.0, {10.0, 20.0, 30.0}};

hal::HapticSample sample_at(double x, double y, double z, double angle0 = 0.0, double angle1 = 0.0) {
  return hal::HapticSample{{x, y, z}, {angle0, angle1}, 1U, 0U, 1U};
}

hal::HapticCommand command(double fx, double fy, double fz, double t0 = 0.0, double t1 = 0.0) {
  return hal::HapticCommand{{fx, fy, fz}, {t0, t1}, 1U, true};
}

double norm3(const double (&v)[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

TEST_GROUP(HapticRangeChecks){};

TEST(HapticRangeChecks, ASampleIsFiniteOnlyWhenEveryPositionAndAngleIs) {
  CHECK_TRUE(hal::sample_in_range(sample_at(10.0, 20.0, 30.0), kSmallRange));
  CHECK_TRUE(hal::sample_finite(sample_at(1e300, -1e300, 0.0, 1e9, -1e9)));  // huge is still finite
  for (int field = 0; field < 5; ++field) {
    for (const double bad : {kNaN, kInfinity, -kInfinity}) {
      hal::HapticSample sample = sample_at(10.0, 20.0, 30.0);  // the centre: only the bad field can refuse it
      if (field < 3) {
        sample.position_mm[field] = bad;
      } else {
        sample.angles_rad[field - 3] = bad;
      }
      CHECK_FALSE(hal::sample_finite(sample));
      CHECK_FALSE(hal::sample_in_range(sample, kSmallRange));
    }
  }
}

TEST(HapticRangeChecks, TheReachIsMeasuredFromItsCentreAndIncludesItsEdges) {
  CHECK_TRUE(hal::sample_in_range(sample_at(10.0, 20.0, 30.0), kSmallRange));
  CHECK_TRUE(hal::sample_in_range(sample_at(9.0, 22.0, 27.0, 0.5, -0.5), kSmallRange));  // every edge at once
  CHECK_FALSE(hal::sample_in_range(sample_at(0.0, 0.0, 0.0), kSmallRange));  // the origin is not the centre
  CHECK_FALSE(hal::sample_in_range(sample_at(11.001, 20.0, 30.0), kSmallRange));
  CHECK_FALSE(hal::sample_in_range(sample_at(10.0, 17.999, 30.0), kSmallRange));
  CHECK_FALSE(hal::sample_in_range(sample_at(10.0, 20.0, 33.001), kSmallRange));
  CHECK_FALSE(hal::sample_in_range(sample_at(10.0, 20.0, 30.0, 0.501, 0.0), kSmallRange));
  CHECK_FALSE(hal::sample_in_range(sample_at(10.0, 20.0, 30.0, 0.0, -0.501), kSmallRange));
}

TEST(HapticRangeChecks, WithTheOriginAtACornerTheWholeReachIsAcceptedAndNothingPastItsMargin) {
  hal::HapticSample sample{};
  const auto at = [&](double x, double y, double z) {
    sample.position_mm[0] = x;
    sample.position_mm[1] = y;
    sample.position_mm[2] = z;
    return hal::sample_in_range(sample, board::sherline_suzuki::kDeviceRange);
  };
  CHECK_TRUE(at(0.0, 0.0, 0.0));
  CHECK_TRUE(at(500.0, 250.0, 250.0));
  CHECK_TRUE(at(-25.0, 275.0, 125.0));
  CHECK_FALSE(at(525.001, 0.0, 0.0));
  CHECK_FALSE(at(0.0, -25.001, 0.0));
  CHECK_FALSE(at(0.0, 0.0, NAN));
  CHECK_FALSE(hal::sample_in_range(sample, board::sherline_suzuki::kCentredDeviceRange));  // the centred reach says no to z NaN too
  CHECK_TRUE(at(250.0, 125.0, 125.0));
  CHECK_FALSE(hal::sample_in_range(sample, hal::HapticRange{{1.0, 1.0, 1.0}, 3.2, 5.0, 200.0, {0.0, 0.0, 0.0}}));
}

TEST(HapticRangeChecks, ACommandWithinTheLimitsIsPassedOnUnchanged) {
  const hal::ClampedCommand clamped = hal::clamp_command(command(3.0, 4.0, 0.0, 120.0, -160.0), 5.0, 200.0);
  CHECK_TRUE(clamped.finite);
  CHECK_FALSE(clamped.clamped);  // exactly at both limits is not a clamp
  DOUBLES_EQUAL(3.0, clamped.force_n[0], 0.0);
  DOUBLES_EQUAL(4.0, clamped.force_n[1], 0.0);
  DOUBLES_EQUAL(120.0, clamped.torque_nmm[0], 0.0);
  DOUBLES_EQUAL(-160.0, clamped.torque_nmm[1], 0.0);
}

TEST(HapticRangeChecks, AForceTooLargeIsScaledToTheLimitWithItsDirectionKept) {
  const hal::ClampedCommand clamped = hal::clamp_command(command(-6.0, 0.0, 8.0), 5.0, 200.0);  // 10 N
  CHECK_TRUE(clamped.finite);
  CHECK_TRUE(clamped.clamped);
  DOUBLES_EQUAL(-3.0, clamped.force_n[0], 1e-12);
  DOUBLES_EQUAL(0.0, clamped.force_n[1], 0.0);
  DOUBLES_EQUAL(4.0, clamped.force_n[2], 1e-12);
  DOUBLES_EQUAL(5.0, norm3(clamped.force_n), 1e-12);
}

TEST(HapticRangeChecks, ForceAndTorqueAreClampedEachToItsOwnLimit) {
  const hal::ClampedCommand torque_only = hal::clamp_command(command(1.0, 0.0, 0.0, 300.0, -400.0), 5.0, 200.0);
  CHECK_TRUE(torque_only.clamped);
  DOUBLES_EQUAL(1.0, torque_only.force_n[0], 0.0);  // the force was within its limit: untouched
  DOUBLES_EQUAL(120.0, torque_only.torque_nmm[0], 1e-9);
  DOUBLES_EQUAL(-160.0, torque_only.torque_nmm[1], 1e-9);

  const hal::ClampedCommand force_only = hal::clamp_command(command(0.0, 0.0, -9.0, 10.0, 0.0), 2.0, 200.0);
  CHECK_TRUE(force_only.clamped);
  DOUBLES_EQUAL(-2.0, force_only.force_n[2], 1e-12);
  DOUBLES_EQUAL(10.0, force_only.torque_nmm[0], 0.0);
}

TEST(HapticRangeChecks, ACommandWithANaNOrInfinityAnywhereBecomesAllZero) {
  for (int field = 0; field < 5; ++field) {
    for (const double bad : {kNaN, kInfinity, -kInfinity}) {
      hal::HapticCommand given = command(1.0, 2.0, 3.0, 4.0, 5.0);
      if (field < 3) {
        given.force_n[field] = bad;
      } else {
        given.torque_nmm[field - 3] = bad;
      }
      const hal::ClampedCommand clamped = hal::clamp_command(given, 5.0, 200.0);
      CHECK_FALSE(clamped.finite);
      CHECK_FALSE(clamped.clamped);
      for (const double force : clamped.force_n) DOUBLES_EQUAL(0.0, force, 0.0);
      for (const double torque : clamped.torque_nmm) DOUBLES_EQUAL(0.0, torque, 0.0);
    }
  }
}

// Finite values whose sum of squares overflows to infinity: the scale is zero, so the command goes
// out as zero force (never as an infinity or a NaN).
TEST(HapticRangeChecks, AFiniteForceWhoseSquareOverflowsIsScaledToZero) {
  const hal::ClampedCommand clamped = hal::clamp_command(command(1e200, -1e200, 0.0, 0.0, 1e200), 5.0, 200.0);
  CHECK_TRUE(clamped.finite);
  CHECK_TRUE(clamped.clamped);
  for (const double force : clamped.force_n) CHECK_TRUE(std::isfinite(force) && std::fabs(force) <= 5.0);
  for (const double torque : clamped.torque_nmm) CHECK_TRUE(std::isfinite(torque) && std::fabs(torque) <= 200.0);
}

TEST(HapticRangeChecks, AWritesOutcomeIsCountedRejectedClampedOrWritten) {
  hal::HapticCounters counters{};
  const hal::WriteResult written = hal::write_outcome(hal::clamp_command(command(1.0, 0.0, 0.0), 5.0, 200.0), counters);
  CHECK_EQUAL(WriteStatus::Written, written.status);
  CHECK_EQUAL(HapticFault::None, written.reason);

  const hal::WriteResult clamped = hal::write_outcome(hal::clamp_command(command(9.0, 0.0, 0.0), 5.0, 200.0), counters);
  CHECK_EQUAL(WriteStatus::Clamped, clamped.status);
  CHECK_EQUAL(HapticFault::None, clamped.reason);

  const hal::WriteResult rejected = hal::write_outcome(hal::clamp_command(command(kNaN, 0.0, 0.0), 5.0, 200.0), counters);
  CHECK_EQUAL(WriteStatus::Rejected, rejected.status);
  CHECK_EQUAL(HapticFault::CommandNotFinite, rejected.reason);

  CHECK_EQUAL(1U, counters.commands_clamped);
  CHECK_EQUAL(1U, counters.commands_rejected);
  CHECK_EQUAL(0U, counters.samples_accepted);  // nothing else is touched
}

TEST(HapticRangeChecks, UnitsOnTheWireAreRoundedTowardZeroSoAClampNeverGrows) {
  CHECK_EQUAL(4999, hal::to_units_toward_zero(4.9999, 1e3));
  CHECK_EQUAL(-4999, hal::to_units_toward_zero(-4.9999, 1e3));
  CHECK_EQUAL(5000, hal::to_units_toward_zero(5.0, 1e3));
  CHECK_EQUAL(12345, hal::to_units_toward_zero(123.459, 100.0));
  CHECK_EQUAL(0, hal::to_units_toward_zero(-0.0009, 1e3));

  // The diagonal at 5 N: each component rounded down, the magnitude on the wire within 5000 mN.
  const hal::ClampedCommand clamped = hal::clamp_command(command(100.0, -100.0, 100.0), 5.0, 200.0);
  std::int64_t squared = 0;
  for (const double force : clamped.force_n) {
    const std::int64_t units = hal::to_units_toward_zero(force, 1e3);
    squared += units * units;
  }
  CHECK_TRUE(squared <= std::int64_t{5000} * 5000);
}
