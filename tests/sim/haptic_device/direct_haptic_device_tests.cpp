// DirectHapticDevice (sim/haptic_device/direct_haptic_device.hpp) for what is its own beyond the
// HapticDevice contract (tests/hal/haptic_device_tests.cpp runs that on it): a published pose
// rounded to whole micrometres and microradians as the PIO words carry it, values no wire could carry
// left for the range checks, and the command it renders (zero before the first write, with enable off
// and for a non-finite command; clamped; the cycle counter echoed).
#include <cmath>
#include <limits>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "sim/haptic_device/direct_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using hal::ReadStatus;
using hal::WriteStatus;

namespace {

hal::HapticSample sample_at(double x, double y, double z, double angle0 = 0.0, double angle1 = 0.0) {
  return hal::HapticSample{{x, y, z}, {angle0, angle1}, 1U, 0U, 1U};
}

}  // namespace

TEST_GROUP(DirectHapticDevice) {
  sim::DirectHapticDevice device{board::sherline_suzuki::kCentredDeviceRange};
  hal::HapticSample out{};
};

TEST(DirectHapticDevice, APoseIsRoundedToWholeMicrometresAndMicroradiansAsTheWindowCarriesIt) {
  device.publish(sample_at(1.0004, -1.0006, 0.0000004, 0.1234564, -0.1234566));
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  DOUBLES_EQUAL(1.000, out.position_mm[0], 1e-12);
  DOUBLES_EQUAL(-1.001, out.position_mm[1], 1e-12);
  DOUBLES_EQUAL(0.0, out.position_mm[2], 1e-12);
  DOUBLES_EQUAL(0.123456, out.angles_rad[0], 1e-12);
  DOUBLES_EQUAL(-0.123457, out.angles_rad[1], 1e-12);
}

TEST(DirectHapticDevice, AValueNoWireCouldCarryIsRefusedAsOutOfRange) {
  // 3e6 mm is 3e9 um, past 2^31: a wire would saturate it; here it is passed on unrounded, and refused.
  device.publish(sample_at(3e6, 0.0, 0.0));
  const hal::ReadResult far = device.read_sample(0, out);
  CHECK_EQUAL(ReadStatus::Rejected, far.status);
  CHECK_EQUAL(HapticFault::SampleOutOfRange, far.reason);

  device.publish(sample_at(0.0, 0.0, 0.0, std::numeric_limits<double>::quiet_NaN(), 0.0));
  const hal::ReadResult nan = device.read_sample(0, out);
  CHECK_EQUAL(ReadStatus::Rejected, nan.status);
  CHECK_EQUAL(HapticFault::SampleNotFinite, nan.reason);  // not finite is named before out of range
  CHECK_EQUAL(2U, device.counters().samples_out_of_range);
}

TEST(DirectHapticDevice, EachPublishIsNewEvenWithTheSameNumbers) {
  device.publish(sample_at(1.0, 2.0, 3.0));
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  device.publish(sample_at(1.0, 2.0, 3.0));  // same counter, same pose: the handle held still
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  CHECK_EQUAL(ReadStatus::Stale, device.read_sample(0, out).status);
}

TEST(DirectHapticDevice, ItRendersNothingBeforeTheFirstWrite) {
  const hal::HapticCommand& rendered = device.rendered();
  CHECK_FALSE(rendered.enable);
  for (const double force : rendered.force_n) DOUBLES_EQUAL(0.0, force, 0.0);
  for (const double torque : rendered.torque_nmm) DOUBLES_EQUAL(0.0, torque, 0.0);
}

TEST(DirectHapticDevice, ItRendersTheCommandClampedWithItsCycleCounter) {
  const hal::WriteResult result = device.write_command(hal::HapticCommand{{0.0, 30.0, -40.0}, {0.0, 250.0}, 42U, true});
  CHECK_EQUAL(WriteStatus::Clamped, result.status);
  const hal::HapticCommand& rendered = device.rendered();
  CHECK_TRUE(rendered.enable);
  DOUBLES_EQUAL(3.0, rendered.force_n[1], 1e-12);
  DOUBLES_EQUAL(-4.0, rendered.force_n[2], 1e-12);
  DOUBLES_EQUAL(200.0, rendered.torque_nmm[1], 1e-12);
  CHECK_EQUAL(42U, rendered.cycle_counter);
}

TEST(DirectHapticDevice, WithEnableOffItRendersZeroWhateverTheNumbers) {
  CHECK_EQUAL(WriteStatus::Written, device.write_command(hal::HapticCommand{{1.0, 2.0, 3.0}, {4.0, 5.0}, 9U, true}).status);
  CHECK_EQUAL(WriteStatus::Written, device.write_command(hal::HapticCommand{{1.0, 2.0, 3.0}, {4.0, 5.0}, 10U, false}).status);
  const hal::HapticCommand& rendered = device.rendered();
  CHECK_FALSE(rendered.enable);
  for (const double force : rendered.force_n) DOUBLES_EQUAL(0.0, force, 0.0);
  for (const double torque : rendered.torque_nmm) DOUBLES_EQUAL(0.0, torque, 0.0);
  CHECK_EQUAL(10U, rendered.cycle_counter);
}

TEST(DirectHapticDevice, ANonFiniteCommandRendersZeroWithEnableOff) {
  CHECK_EQUAL(WriteStatus::Written, device.write_command(hal::HapticCommand{{1.0, 0.0, 0.0}, {0.0, 0.0}, 1U, true}).status);
  const hal::WriteResult result =
      device.write_command(hal::HapticCommand{{1.0, 0.0, 0.0}, {std::nan(""), 0.0}, 2U, true});
  CHECK_EQUAL(WriteStatus::Rejected, result.status);
  CHECK_EQUAL(HapticFault::CommandNotFinite, result.reason);
  CHECK_FALSE(device.rendered().enable);
  DOUBLES_EQUAL(0.0, device.rendered().force_n[0], 0.0);
}

TEST(DirectHapticDevice, ItIsAlwaysConnectedAndHasNothingToLatch) {
  CHECK_EQUAL(hal::HapticLinkState::Connected, device.link_state());  // before any sample, too
  CHECK_EQUAL(ReadStatus::Stale, device.read_sample(1'000'000'000'000, out).status);
  CHECK_EQUAL(HapticFault::None, device.latched_fault());
}
