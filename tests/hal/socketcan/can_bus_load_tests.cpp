// The haptic frames' load on a classic CAN bus: frame lengths in bits, and the bitrate check the link
// makes when it is opened (refuse a bus too slow for a period's frames).
#include "hal/socketcan/can_bus_load.hpp"

#include "hal/socketcan/can_codec.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil::hal::socketcan;

TEST_GROUP(CanBusLoad) {};

TEST(CanBusLoad, AnEightByteFrameIs111BitsUnstuffedAnd135AtWorstIntermissionIncluded) {
  CHECK_EQUAL(111, classic_frame_bits_unstuffed(8));
  CHECK_EQUAL(135, classic_frame_bits_worst_case(8));
  CHECK_EQUAL(47, classic_frame_bits_unstuffed(0));
  CHECK_EQUAL(55, classic_frame_bits_worst_case(0));  // 34 stuffed bits: 8 stuff bits at most
}

TEST(CanBusLoad, EachHapticFrameOnTheWireLiesBetweenItsUnstuffedAndWorstCaseLength) {
  can_frame pose_a;
  can_frame pose_b;
  can_frame status;
  can_frame force;
  can_frame torque;
  CHECK_TRUE(encode_pose(PoseWire{17, {-123456, 250000, 0}, {-31416, 15708}}, pose_a, pose_b));
  encode_status(StatusWire{17, 0x000F, 0xFFFFFFFFU}, status);
  encode_command(CommandWire{3, {5000, -5000, 0}, {20000, -20000}, 65535, true}, force, torque);
  for (const can_frame& frame : {pose_a, pose_b, status, force, torque}) {
    const int bits = classic_frame_bits(frame);
    CHECK_TRUE(bits >= classic_frame_bits_unstuffed(8));
    CHECK_TRUE(bits <= classic_frame_bits_worst_case(8));
  }
  // Long runs of equal bits cost stuff bits: all zeros or all ones are longer than alternating bytes.
  can_frame zeros{};
  zeros.can_id = 0x000;
  zeros.len = 8;
  can_frame alternating = zeros;
  alternating.can_id = 0x555;
  for (std::uint8_t& byte : alternating.data) byte = 0x55;
  CHECK_TRUE(classic_frame_bits(zeros) > classic_frame_bits(alternating));
  CHECK_TRUE(classic_frame_bits(alternating) < classic_frame_bits_unstuffed(8) + 4);
  // By hand: identifier 0 with no data sends 34 zeros (SOF, identifier, RTR, IDE, r0, DLC and a zero
  // CRC); a stuff bit follows every fifth: 6 of them, 47 + 6 bits.
  can_frame empty{};
  CHECK_EQUAL(53, classic_frame_bits(empty));
}

TEST(CanBusLoad, TheHapticFrameSetIsFiveEightByteFramesEveryMillisecond) {
  CHECK_EQUAL(3, kDeviceFramesPerPeriod);
  CHECK_EQUAL(2, kHostFramesPerPeriod);
  CHECK_EQUAL(5, kHapticFramesPerPeriod);
  CHECK_EQUAL(1'000'000, kFramePeriodNs);
}

TEST(CanBusLoad, A500KbitBusCannotCarryAPeriodsFramesAndIsRefused) {
  const BusLoad load = haptic_bus_load(500'000);
  CHECK_FALSE(load.fits);
  CHECK_EQUAL(675U, load.worst_case_bits_per_period);
  CHECK_EQUAL(555U, load.unstuffed_bits_per_period);
  CHECK_EQUAL(500U, load.bits_available_per_period);
  DOUBLES_EQUAL(1.35, load.worst_case_load, 1e-12);
  DOUBLES_EQUAL(1.11, load.unstuffed_load, 1e-12);  // too much even with no stuff bit at all
  CHECK_EQUAL(675'000U, load.bitrate_needed_bps);
}

TEST(CanBusLoad, A1MbitBusCarriesThemWithRoomToSpare) {
  const BusLoad load = haptic_bus_load(1'000'000);
  CHECK_TRUE(load.fits);
  DOUBLES_EQUAL(0.675, load.worst_case_load, 1e-12);
  DOUBLES_EQUAL(0.555, load.unstuffed_load, 1e-12);
  CHECK_EQUAL(675'000U, load.bitrate_needed_bps);
}

TEST(CanBusLoad, TheNeededBitrateFollowsFromTheFrameSetNotAFixedNumber) {
  CHECK_TRUE(haptic_bus_load(675'000).fits);  // exactly full at worst
  CHECK_FALSE(haptic_bus_load(674'999).fits);
  CHECK_TRUE(haptic_bus_load(800'000).fits);
  CHECK_FALSE(haptic_bus_load(250'000).fits);
  CHECK_FALSE(haptic_bus_load(0).fits);
  // Another frame set or period: three 8-byte frames every 2 ms need 405 bits per 2 ms.
  const BusLoad three = bus_load(3, 8, 2'000'000, 250'000);
  CHECK_TRUE(three.fits);
  CHECK_EQUAL(202'500U, three.bitrate_needed_bps);
  DOUBLES_EQUAL(0.81, three.worst_case_load, 1e-12);
}
