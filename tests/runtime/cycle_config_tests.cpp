// The cycle's configuration from a board's facts (runtime/cycle_config.hpp): each fact lands where
// the controller reads it, the scale in both the contact's and the haptic output's parameters, the
// device's reach widened by its margin on every side, and the virtual tool's speed turned into a
// per-period move. Facts chosen all different, so a fact put in the wrong place shows.
#include <cmath>

#include <Eigen/Core>

#include "firmware/runtime/cycle_config.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

runtime::CycleFacts facts() {
  return {{8.0, Eigen::Vector3d(1.0, 2.0, 3.0), Eigen::Vector3d(25.0, 12.5, 20.0), {-1, -1, 1}, 640.0},
          Eigen::Vector3d(160.0, 120.0, 90.0),
          4.0,
          3.5,
          150.0,
          0.002,
          1.25,
          0.015,
          false};
}

}  // namespace

TEST_GROUP(CycleConfig){};

TEST(CycleConfig, TheFramesAndTheirScaleGoEverywhereTheCycleUsesThem) {
  const control::ControllerConfig config = runtime::controller_config(facts());
  DOUBLES_EQUAL(8.0, config.frames.device_mm_per_world_mm, 0.0);
  CHECK(config.frames.device_origin_mm == Eigen::Vector3d(1.0, 2.0, 3.0));
  CHECK(config.frames.machine_sign == (std::array<int, 3>{-1, -1, 1}));
  DOUBLES_EQUAL(640.0, config.frames.steps_per_mm, 0.0);
  DOUBLES_EQUAL(8.0, config.contact.device_mm_per_world_mm, 0.0);
  DOUBLES_EQUAL(8.0, config.haptic.device_mm_per_world_mm, 0.0);
  // The virtual tool starts where the machine's home puts the tool.
  CHECK(config.home_tip_mm == Eigen::Vector3d(25.0, 12.5, 20.0));
}

TEST(CycleConfig, TheDevicesReachIsItsWorkspaceWidenedByTheMarginOnEverySide) {
  const control::ControllerConfig config = runtime::controller_config(facts());
  CHECK(config.device_low_mm == Eigen::Vector3d(-4.0, -4.0, -4.0));
  CHECK(config.device_high_mm == Eigen::Vector3d(164.0, 124.0, 94.0));
}

TEST(CycleConfig, TheLimitsThePeriodAndTheStandoffAreTheBoards) {
  const control::ControllerConfig config = runtime::controller_config(facts());
  DOUBLES_EQUAL(3.5, config.haptic.max_force_n, 0.0);
  DOUBLES_EQUAL(150.0, config.haptic.max_torque_nmm, 0.0);
  DOUBLES_EQUAL(0.002, config.period_s, 0.0);
  DOUBLES_EQUAL(0.015, config.standoff_mm, 0.0);
  CHECK_FALSE(config.count_overruns);
  CHECK(runtime::controller_config([] {
          runtime::CycleFacts f = facts();
          f.count_overruns = true;
          return f;
        }())
            .count_overruns);
}

TEST(CycleConfig, TheVirtualToolMovesPerPeriodWhatTheMillFollowsOnEachAxisAndAllTogether) {
  const control::ControllerConfig config = runtime::controller_config(facts());
  DOUBLES_EQUAL(1.25 * 0.002, config.max_axis_move_mm, 1e-18);
  DOUBLES_EQUAL(1.25 * 0.002, config.max_total_move_mm, 1e-18);
}

TEST(CycleConfig, WhatTheBoardDoesNotSayKeepsTheControllersDefaults) {
  const control::ControllerConfig config = runtime::controller_config(facts());
  const control::ControllerConfig defaults{};
  LONGS_EQUAL(defaults.stale_periods, config.stale_periods);
  DOUBLES_EQUAL(defaults.reset_distance_mm, config.reset_distance_mm, 0.0);
  DOUBLES_EQUAL(defaults.haptic.coupling_n_per_device_mm, config.haptic.coupling_n_per_device_mm, 0.0);
  DOUBLES_EQUAL(defaults.contact.stiffness_n_per_device_mm, config.contact.stiffness_n_per_device_mm, 0.0);
  CHECK(config.start_held == defaults.start_held);
}
