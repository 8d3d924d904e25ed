// A pose source for the simulated device whose every field follows from the sample counter, so a
// sample mixed from two writes (or mis-paired frames) fails consistent_with_counter(). Shared by the
// haptic tests of both backends and of the simulated device.
#pragma once

#include <cmath>
#include <cstdint>

#include "hal/haptic_device.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"

namespace stencil::test {

// Positions on whole micrometres and angles on whole 100 urad steps: exact on both wires.
inline sim::SimulatedPose counter_pose(std::uint32_t k, hal::MonotonicNs) {
  const double cycle = static_cast<double>(k % 2000U);
  return {{cycle * 0.1 - 100.0, -cycle * 0.05, cycle * 0.025}, {cycle * 1e-3 - 1.0, 1.0 - cycle * 5e-4}};
}

// The simulated device beats once per sample from the same start, so the heartbeat equals the counter.
inline bool consistent_with_counter(const hal::HapticSample& sample) {
  const sim::SimulatedPose expected = counter_pose(sample.sample_counter, 0);
  for (int axis = 0; axis < 3; ++axis) {
    if (std::fabs(sample.position_mm[axis] - expected.position_mm[axis]) > 1e-6) return false;
  }
  for (int angle = 0; angle < 2; ++angle) {
    if (std::fabs(sample.angles_rad[angle] - expected.angles_rad[angle]) > 1e-6) return false;
  }
  return sample.device_heartbeat == sample.sample_counter;
}

}  // namespace stencil::test
