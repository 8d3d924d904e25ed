// saturated_units: physical values to the wire's integers, rounded to the nearest unit and held at
// the field's limits (the simulated device may be told to send more than a wire carries), NaN as 0.
#include <cstdint>
#include <limits>

#include "sim/haptic_device/wire_units.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using stencil::sim::saturated_units;

TEST_GROUP(WireUnits){};

TEST(WireUnits, ValuesAreScaledAndRoundedToTheNearestUnitHalvesAwayFromZero) {
  LONGS_EQUAL(1235, saturated_units(1.2345, 1e3));  // 1234.5 rounds up
  LONGS_EQUAL(-1235, saturated_units(-1.2345, 1e3));
  LONGS_EQUAL(1234, saturated_units(1.23449, 1e3));
  LONGS_EQUAL(0, saturated_units(0.0004, 1e3));
}

TEST(WireUnits, ValuesBeyondTheFieldAreHeldAtItsLimits) {
  LONGS_EQUAL(std::numeric_limits<std::int32_t>::max(), saturated_units(1e12, 1e3));
  LONGS_EQUAL(std::numeric_limits<std::int32_t>::lowest(), saturated_units(-1e12, 1e3));
  LONGS_EQUAL(32767, saturated_units<std::int16_t>(1e9, 1.0));
  LONGS_EQUAL(-32768, saturated_units<std::int16_t>(-1e9, 1.0));
  // Given limits narrower than the type (int24 in an int32 field).
  LONGS_EQUAL((1 << 23) - 1, saturated_units(1e5, 1e3, -(1 << 23), (1 << 23) - 1));
  LONGS_EQUAL(-(1 << 23), saturated_units(-1e5, 1e3, -(1 << 23), (1 << 23) - 1));
  LONGS_EQUAL(8'000'000, saturated_units(8000.0, 1e3, -(1 << 23), (1 << 23) - 1));  // inside: untouched
}

TEST(WireUnits, InfinitiesSaturateAndNotANumberIsZero) {
  LONGS_EQUAL(std::numeric_limits<std::int32_t>::max(), saturated_units(std::numeric_limits<double>::infinity(), 1.0));
  LONGS_EQUAL(std::numeric_limits<std::int32_t>::lowest(), saturated_units(-std::numeric_limits<double>::infinity(), 1.0));
  LONGS_EQUAL(0, saturated_units(std::numeric_limits<double>::quiet_NaN(), 1.0));
}
