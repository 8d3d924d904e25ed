// The cycle's velocity estimate (stencil/velocity_filter.hpp): the backward difference through a
// first-order low-pass at the configured corner.
#include <cmath>

#include <Eigen/Core>

#include "firmware/core/stencil/velocity_filter.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using stencil::engine::VelocityFilter;

TEST_GROUP(VelocityFilter){};

TEST(VelocityFilter, TheFirstSampleGivesZeroAndASteadyMotionSettlesOnItsSpeed) {
  VelocityFilter filter;
  filter.configure(100.0, 1e-3);
  CHECK(filter.update(Eigen::Vector3d(5.0, 0.0, 0.0)).isZero());
  Eigen::Vector3d estimate;
  for (int i = 1; i <= 200; ++i) {
    estimate = filter.update(Eigen::Vector3d(5.0 + 0.02 * i, 0.0, -0.01 * i));  // 20 and -10 per second
  }
  DOUBLES_EQUAL(20.0, estimate.x(), 1e-6);
  DOUBLES_EQUAL(-10.0, estimate.z(), 1e-6);
}

TEST(VelocityFilter, AStepInSpeedIsFollowedWithTheLowPasssTimeConstant) {
  // 100 Hz at 1 kHz: alpha = wT / (1 + wT), so after n samples the estimate has 1 - (1 - alpha)^n of a step.
  VelocityFilter filter;
  filter.configure(100.0, 1e-3);
  const double omega_t = 2.0 * 3.14159265358979323846 * 100.0 * 1e-3;
  DOUBLES_EQUAL(omega_t / (1.0 + omega_t), filter.alpha(), 1e-12);
  static_cast<void>(filter.update(Eigen::Vector3d::Zero()));
  double x = 0.0;
  for (int n = 1; n <= 5; ++n) {
    x += 1e-3;  // 1 per second from here on
    DOUBLES_EQUAL(1.0 - std::pow(1.0 - filter.alpha(), n), filter.update(Eigen::Vector3d(x, 0.0, 0.0)).x(), 1e-12);
  }
}

TEST(VelocityFilter, ACornerAtOrAboveNyquistOrNotANumberPassesTheRawDifference) {
  for (const double cutoff : {500.0, 2000.0, 0.0, -1.0, std::nan("")}) {
    VelocityFilter filter;
    filter.configure(cutoff, 1e-3);
    DOUBLES_EQUAL(1.0, filter.alpha(), 0.0);
    static_cast<void>(filter.update(Eigen::Vector3d::Zero()));
    DOUBLES_EQUAL(3.0, filter.update(Eigen::Vector3d(3e-3, 0.0, 0.0)).x(), 1e-9);
  }
}

TEST(VelocityFilter, AfterAResetTheNextSampleStartsAgainFromZero) {
  VelocityFilter filter;
  filter.configure(100.0, 1e-3);
  static_cast<void>(filter.update(Eigen::Vector3d::Zero()));
  static_cast<void>(filter.update(Eigen::Vector3d(1.0, 0.0, 0.0)));
  CHECK(filter.value().x() > 0.0);
  filter.reset();
  CHECK(filter.value().isZero());
  CHECK(filter.update(Eigen::Vector3d(50.0, 0.0, 0.0)).isZero());  // no jump from the gap
}

TEST(VelocityFilter, ASampleAfterAGapIsDifferencedOverTheTimeSinceTheLastOne) {
  // A steady 10 per second, with the third sample two periods after the second (a stale read).
  VelocityFilter filter;
  filter.configure(1000.0, 1e-3);  // at Nyquist: the raw difference passes
  static_cast<void>(filter.update(Eigen::Vector3d::Zero()));
  DOUBLES_EQUAL(10.0, filter.update(Eigen::Vector3d(0.01, 0.0, 0.0)).x(), 1e-9);
  DOUBLES_EQUAL(10.0, filter.update(Eigen::Vector3d(0.03, 0.0, 0.0), 2e-3).x(), 1e-9);
}
