// When each step of a CY545 move happens: constant slew rate, or the F -> R -> F ramp set by the slope.
#pragma once

#include <cstdint>

namespace stencil::sim::cy545 {

class MoveProfile {
 public:
  // A move of `steps` steps at slew rate `rate` and first rate `first_rate` (steps/s) with slope
  // `slope` (0..255). No ramp when slope is 0 or first_rate >= rate.
  MoveProfile(std::uint32_t steps, std::uint32_t rate, std::uint32_t first_rate, std::uint32_t slope);

  // Time of step k (1..steps) after the start, in ns. Step `steps` ends the move.
  [[nodiscard]] std::int64_t step_offset_ns(std::uint32_t k) const;
  [[nodiscard]] std::int64_t duration_ns() const { return steps_ == 0 ? 0 : step_offset_ns(steps_); }
  [[nodiscard]] std::uint32_t steps() const { return steps_; }
  [[nodiscard]] bool ramped() const { return ramped_; }

  // The manual's approximate acceleration for a slope value (steps/s^2, 12 MHz, first rate gap D = 25).
  static double acceleration_steps_per_s2(std::uint32_t slope);

 private:
  // Seconds to cover `distance` steps accelerating from the first rate.
  [[nodiscard]] double accelerating_seconds(double distance) const;

  std::uint32_t steps_;
  std::uint32_t rate_;
  double first_rate_ = 0.0;
  double acceleration_ = 0.0;
  bool ramped_ = false;
  double ramp_steps_ = 0.0;     // steps spent accelerating (and as many decelerating)
  double total_seconds_ = 0.0;
};

}  // namespace stencil::sim::cy545
