// Small values the haptic backends' tests share: a sample no backend would write (to see that a read
// left `out` untouched) and a force command in newtons.
#pragma once

#include "hal/haptic_device.hpp"

namespace stencil::test {

// Position x 12345 mm and counter 0xDEAD: beyond any reach, so a read that wrote it would show.
inline hal::HapticSample marker_sample() {
  hal::HapticSample sample{};
  sample.position_mm[0] = 12345.0;
  sample.sample_counter = 0xDEADU;
  return sample;
}

// Force in newtons, no torque, cycle counter 7.
inline hal::HapticCommand command_of(double fx, double fy, double fz, bool enable = true) {
  return hal::HapticCommand{{fx, fy, fz}, {0.0, 0.0}, 7, enable};
}

}  // namespace stencil::test
