// The velocity past the filter's lag (stencil/velocity_predictor.hpp): what the committed forces did
// to a free nominal mass, added to the filtered estimate before the filter shows it.
#include <cmath>

#include <Eigen/Core>

#include "firmware/core/stencil/velocity_filter.hpp"
#include "firmware/core/stencil/velocity_predictor.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using stencil::engine::VelocityFilter;
using stencil::engine::VelocityPredictor;

namespace {

constexpr double kPeriodS = 1e-3;
constexpr double kDelayS = 0.7e-3;

// A free mass of the nominal mass at 1 kHz, a force held over each period after the link's delay, its
// positions through the velocity filter, and the predictor beside it.
struct FreeMass {
  VelocityFilter filter;
  VelocityPredictor predictor;
  double position_m = 0.0;
  double velocity_m_per_s = 0.0;
  double force_before_n = 0.0;

  explicit FreeMass(double balance_cutoff_hz = VelocityPredictor::kBalanceCutoffHz) {
    filter.configure(VelocityFilter::kDefaultCutoffHz, kPeriodS);
    predictor.configure(filter.alpha(), kPeriodS, kDelayS, VelocityPredictor::kNominalMassKg, balance_cutoff_hz);
    static_cast<void>(filter.update(Eigen::Vector3d::Zero()));
    predictor.sample();
  }

  // One period: the force commanded now acts from the delay on; then the next sample is taken.
  void period(double force_n) {
    predictor.commit({force_n, 0.0, 0.0});
    const double m = VelocityPredictor::kNominalMassKg;
    for (const auto& [force, seconds] : {std::pair{force_before_n, kDelayS}, std::pair{force_n, kPeriodS - kDelayS}}) {
      position_m += velocity_m_per_s * seconds + 0.5 * force / m * seconds * seconds;
      velocity_m_per_s += force / m * seconds;
    }
    force_before_n = force_n;
    static_cast<void>(filter.update({position_m, 0.0, 0.0}));
    predictor.sample();
  }

  [[nodiscard]] double filtered() const { return filter.value().x(); }
  [[nodiscard]] double predicted() const { return predictor.predict(filter.value()).x(); }
  // What the velocity will be when the next command takes over, after the link's delay.
  [[nodiscard]] double ahead() const {
    return velocity_m_per_s + force_before_n / VelocityPredictor::kNominalMassKg * kDelayS;
  }
};

}  // namespace

TEST_GROUP(VelocityPredictor){};

TEST(VelocityPredictor, WithNoForceItGivesTheFiltersEstimateBack) {
  VelocityPredictor predictor;
  predictor.configure(0.4, kPeriodS, kDelayS);
  predictor.sample();
  const Eigen::Vector3d estimate(0.01, -0.02, 0.003);
  CHECK(predictor.predict(estimate) == estimate);
}

TEST(VelocityPredictor, OnTheNominalMassWithNothingTakenAsBalancedThePredictionIsExact) {
  FreeMass mass(1e-9);
  for (int i = 0; i < 5; ++i) {
    mass.period(1.0);  // 1 N on 0.3 kg: 3.3 mm/s more each period
  }
  CHECK(std::fabs(mass.filtered() - mass.ahead()) > 5e-3);  // the filter trails by more than a period's change
  DOUBLES_EQUAL(mass.ahead(), mass.predicted(), 1e-9);
}

TEST(VelocityPredictor, APushOnTheNominalMassShowsAtOnceWhereTheFilterLagsBehind) {
  FreeMass mass;
  for (int i = 0; i < 5; ++i) {
    mass.period(1.0);
  }
  const double filter_error = std::fabs(mass.filtered() - mass.ahead());
  const double predictor_error = std::fabs(mass.predicted() - mass.ahead());
  // Most of the gap closed; what is left is the push's first 5 ms taken as the hand's (10 Hz).
  CHECK(predictor_error < 0.25 * filter_error);
}

TEST(VelocityPredictor, ASteadyForceIsTakenAsTheHandsPushBalancedAndPredictsNothing) {
  // The handle holds still against a steady 2 N (the hand pushes back as hard): after a few tenths of
  // a second of it the prediction is the filter's estimate again.
  VelocityFilter filter;
  filter.configure(VelocityFilter::kDefaultCutoffHz, kPeriodS);
  VelocityPredictor predictor;
  predictor.configure(filter.alpha(), kPeriodS, kDelayS);
  for (int i = 0; i < 400; ++i) {
    predictor.commit({2.0, 0.0, 0.0});
    static_cast<void>(filter.update(Eigen::Vector3d::Zero()));
    predictor.sample();
  }
  DOUBLES_EQUAL(0.0, predictor.predict(filter.value()).x(), 1e-5);
}

TEST(VelocityPredictor, AResetForgetsTheForces) {
  VelocityPredictor predictor;
  predictor.configure(0.4, kPeriodS, kDelayS);
  for (int i = 0; i < 3; ++i) {
    predictor.commit({0.0, 3.0, 0.0});
    predictor.sample();
  }
  CHECK(predictor.predict(Eigen::Vector3d::Zero()).norm() > 0.0);
  predictor.reset();
  CHECK(predictor.predict(Eigen::Vector3d::Zero()).isZero());
}

TEST(VelocityPredictor, AMassThatIsNotAPositiveNumberPredictsNothing) {
  VelocityPredictor predictor;
  predictor.configure(0.4, kPeriodS, kDelayS, 0.0);
  predictor.commit({5.0, 0.0, 0.0});
  predictor.sample();
  CHECK(predictor.predict(Eigen::Vector3d::Zero()).isZero());
  predictor.commit({std::nan(""), 0.0, 0.0});  // refused: the state stays finite
  CHECK(predictor.predict(Eigen::Vector3d::Zero()).allFinite());
}
