// Step times of a CY545 move: k/R exactly without a ramp; a symmetric trapezoid (or triangle) with one.
#include "sim/cy545/move_profile.hpp"

#include <algorithm>
#include <cmath>

#include "hal/clock.hpp"

namespace stencil::sim::cy545 {

double MoveProfile::acceleration_steps_per_s2(std::uint32_t slope) {
  return 3906.0 * 25.0 / (256.0 - static_cast<double>(slope));
}

MoveProfile::MoveProfile(std::uint32_t steps, std::uint32_t rate, std::uint32_t first_rate, std::uint32_t slope)
    : steps_(steps), rate_(rate) {
  ramped_ = slope > 0 && first_rate < rate;
  if (!ramped_) return;
  first_rate_ = static_cast<double>(first_rate);
  acceleration_ = acceleration_steps_per_s2(slope);
  const double slew = static_cast<double>(rate);
  const double full_ramp_steps = (slew * slew - first_rate_ * first_rate_) / (2.0 * acceleration_);
  const double half = static_cast<double>(steps) / 2.0;
  ramp_steps_ = std::min(full_ramp_steps, half);
  const double cruise_steps = static_cast<double>(steps) - 2.0 * ramp_steps_;
  total_seconds_ = 2.0 * accelerating_seconds(ramp_steps_) + cruise_steps / slew;
}

double MoveProfile::accelerating_seconds(double distance) const {
  // distance = F t + a t^2 / 2
  return (std::sqrt(first_rate_ * first_rate_ + 2.0 * acceleration_ * distance) - first_rate_) / acceleration_;
}

std::int64_t MoveProfile::step_offset_ns(std::uint32_t k) const {
  if (!ramped_) {
    return static_cast<std::int64_t>(k) * hal::kNsPerSecond / static_cast<std::int64_t>(rate_);
  }
  const double position = static_cast<double>(k);
  const double total = static_cast<double>(steps_);
  double seconds = 0.0;
  if (position <= ramp_steps_) {
    seconds = accelerating_seconds(position);
  } else if (position <= total - ramp_steps_) {
    seconds = accelerating_seconds(ramp_steps_) + (position - ramp_steps_) / static_cast<double>(rate_);
  } else {
    seconds = total_seconds_ - accelerating_seconds(total - position);
  }
  return static_cast<std::int64_t>(std::llround(seconds * static_cast<double>(hal::kNsPerSecond)));
}

}  // namespace stencil::sim::cy545
