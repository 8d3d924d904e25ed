// Physical values to wire integers for the simulated device: rounded, and saturated to what the
// field can carry (the simulated device may be told to send values beyond the host's range).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace stencil::sim {

template <class Integer = std::int32_t>
[[nodiscard]] inline Integer saturated_units(double value, double units_per_value,
                                             double lowest = std::numeric_limits<Integer>::lowest(),
                                             double highest = std::numeric_limits<Integer>::max()) {
  const double units = std::round(value * units_per_value);
  if (std::isnan(units)) return 0;
  if (units <= lowest) return static_cast<Integer>(lowest);
  if (units >= highest) return static_cast<Integer>(highest);
  return static_cast<Integer>(units);
}

}  // namespace stencil::sim
