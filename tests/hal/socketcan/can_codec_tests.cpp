// The haptic CAN codec: the documented byte layout, round trips at the range limits, and every kind
// of bad frame refused, counted and never applied, on both sides.
#include <cstring>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "tests/hal/socketcan/can_strings.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil::hal;
using namespace stencil::hal::socketcan;

namespace {

// A range wider than the wire, so the round trips reach the int24 limits.
constexpr HapticRange kWideRange{{9000.0, 9000.0, 9000.0}, 4.0, 5.0, 200.0, {0.0, 0.0, 0.0}};

can_frame frame_of(canid_t id, std::initializer_list<std::uint8_t> bytes) {
  can_frame frame{};
  frame.can_id = id;
  frame.len = static_cast<std::uint8_t>(bytes.size());
  std::uint8_t index = 0;
  for (const std::uint8_t byte : bytes) frame.data[index++] = byte;
  return frame;
}

void check_same_pose(const PoseWire& expected, const PoseWire& actual) {
  CHECK_EQUAL(expected.counter, actual.counter);
  for (int axis = 0; axis < 3; ++axis) CHECK_EQUAL(expected.position_um[axis], actual.position_um[axis]);
  for (int angle = 0; angle < 2; ++angle) CHECK_EQUAL(expected.angles_100urad[angle], actual.angles_100urad[angle]);
}

void check_same_command(const CommandWire& expected, const CommandWire& actual) {
  CHECK_EQUAL(expected.counter, actual.counter);
  for (int axis = 0; axis < 3; ++axis) CHECK_EQUAL(expected.force_mn[axis], actual.force_mn[axis]);
  for (int axis = 0; axis < 2; ++axis) CHECK_EQUAL(expected.torque_10mnmm[axis], actual.torque_10mnmm[axis]);
  CHECK_EQUAL(expected.host_heartbeat, actual.host_heartbeat);
  CHECK_EQUAL(expected.enable, actual.enable);
}

}  // namespace

TEST_GROUP(CanCodec) {};

TEST(CanCodec, LaysThePoseOutLittleEndianAsDocumented) {
  can_frame pose_a;
  can_frame pose_b;
  CHECK_TRUE(encode_pose(PoseWire{0x5A, {-2, 0x123456, kInt24Min}, {-1, 0x1234}}, pose_a, pose_b));
  CHECK_EQUAL(kPoseAId, pose_a.can_id);
  CHECK_EQUAL(8, pose_a.len);
  const std::uint8_t expected_a[8] = {0x5A, 0xFE, 0xFF, 0xFF, 0x56, 0x34, 0x12, 0x00};
  MEMCMP_EQUAL(expected_a, pose_a.data, 8);
  CHECK_EQUAL(kPoseBId, pose_b.can_id);
  const std::uint8_t expected_b[8] = {0x5A, 0x00, 0x00, 0x80, 0xFF, 0xFF, 0x34, 0x12};
  MEMCMP_EQUAL(expected_b, pose_b.data, 8);

  can_frame status;
  encode_status(StatusWire{3, 0x0102, 0x0A0B0C0DU}, status);
  const std::uint8_t expected_status[8] = {3, 0x02, 0x01, 0x0D, 0x0C, 0x0B, 0x0A, 0};
  MEMCMP_EQUAL(expected_status, status.data, 8);

  can_frame force;
  can_frame torque;
  encode_command(CommandWire{9, {-1, 5000, 0}, {20000, -20000}, 0xBEEF, true}, force, torque);
  const std::uint8_t expected_force[8] = {9, 0xFF, 0xFF, 0x88, 0x13, 0x00, 0x00, 0x01};
  MEMCMP_EQUAL(expected_force, force.data, 8);
  const std::uint8_t expected_torque[8] = {9, 0x20, 0x4E, 0xE0, 0xB1, 0xEF, 0xBE, 0x00};
  MEMCMP_EQUAL(expected_torque, torque.data, 8);
}

TEST(CanCodec, PoseRoundTripsAtTheLimitsOfItsFields) {
  HostFrameAssembler host(kWideRange);
  const PoseWire extremes[] = {
      {255, {kInt24Min, kInt24Max, -1}, {-32768, 32767}},
      {0, {kInt24Max, 0, kInt24Min}, {0, -1}},
      {128, {1, -1, 0}, {1, -32767}},
  };
  for (const PoseWire& pose : extremes) {
    can_frame pose_a;
    can_frame pose_b;
    CHECK_TRUE(encode_pose(pose, pose_a, pose_b));
    CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
    CHECK_EQUAL(FrameEffect::Completed, host.accept(pose_b).effect);
    check_same_pose(pose, host.latest_pose());
  }
  CHECK_EQUAL(0U, host.rejections().total());
}

TEST(CanCodec, EncodingRefusesAPositionBeyond24Bits) {
  can_frame pose_a;
  can_frame pose_b;
  CHECK_FALSE(encode_pose(PoseWire{1, {0, kInt24Max + 1, 0}, {0, 0}}, pose_a, pose_b));
  CHECK_FALSE(encode_pose(PoseWire{1, {0, 0, kInt24Min - 1}, {0, 0}}, pose_a, pose_b));
}

TEST(CanCodec, StatusRoundTripsAtTheLimitsOfItsFields) {
  HostFrameAssembler host(stencil::board::sherline_suzuki::kCentredDeviceRange);
  for (const StatusWire& status : {StatusWire{255, 0xFFFF, 0xFFFFFFFFU}, StatusWire{0, 0, 0}}) {
    can_frame frame;
    encode_status(status, frame);
    CHECK_EQUAL(FrameEffect::Status, host.accept(frame).effect);
    CHECK_EQUAL(status.counter, host.latest_status().counter);
    CHECK_EQUAL(status.status_bits, host.latest_status().status_bits);
    CHECK_EQUAL(status.device_heartbeat, host.latest_status().device_heartbeat);
  }
}

TEST(CanCodec, APoseAtTheRangeLimitIsAcceptedAndOneStepBeyondIsRefused) {
  HostFrameAssembler host(stencil::board::sherline_suzuki::kCentredDeviceRange);  // 275 x 150 x 150 mm, 3.2 rad
  can_frame pose_a;
  can_frame pose_b;
  CHECK_TRUE(encode_pose(PoseWire{1, {275000, -150000, 150000}, {32000, -32000}}, pose_a, pose_b));
  CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
  CHECK_EQUAL(FrameEffect::Completed, host.accept(pose_b).effect);

  const PoseWire beyond[] = {{2, {275001, 0, 0}, {0, 0}}, {3, {0, -150001, 0}, {0, 0}},
                             {4, {0, 0, 150001}, {0, 0}}, {5, {0, 0, 0}, {32001, 0}},
                             {6, {0, 0, 0}, {0, -32001}}};
  for (const PoseWire& pose : beyond) {
    CHECK_TRUE(encode_pose(pose, pose_a, pose_b));
    CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
    const FrameResult result = host.accept(pose_b);
    CHECK_EQUAL(FrameEffect::Rejected, result.effect);
    CHECK_EQUAL(FrameRejection::OutOfRange, result.rejection);
  }
  CHECK_EQUAL(5U, host.rejections().of(FrameRejection::OutOfRange));
  CHECK_EQUAL(1, host.latest_pose().counter);  // none of them applied
}

TEST(CanCodec, WithTheOriginAtACornerTheWholeReachIsAcceptedAndNothingPastItsMargin) {
  HostFrameAssembler host(stencil::board::sherline_suzuki::kDeviceRange);  // [0, 500] x [0, 250] x [0, 250] mm, 25 mm margin
  can_frame pose_a;
  can_frame pose_b;
  CHECK_TRUE(encode_pose(PoseWire{1, {500000, 250000, 0}, {0, 0}}, pose_a, pose_b));
  CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
  CHECK_EQUAL(FrameEffect::Completed, host.accept(pose_b).effect);
  CHECK_TRUE(encode_pose(PoseWire{2, {-25000, 275000, -25000}, {0, 0}}, pose_a, pose_b));
  CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
  CHECK_EQUAL(FrameEffect::Completed, host.accept(pose_b).effect);
  for (const PoseWire& pose : {PoseWire{3, {525001, 0, 0}, {0, 0}}, PoseWire{4, {0, -25001, 0}, {0, 0}}}) {
    CHECK_TRUE(encode_pose(pose, pose_a, pose_b));
    CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
    CHECK_EQUAL(FrameEffect::Rejected, host.accept(pose_b).effect);
  }
  CHECK_EQUAL(2, host.latest_pose().counter);
}

TEST(CanCodec, CommandRoundTripsAtTheDevicesLimits) {
  DeviceFrameAssembler device;
  const CommandWire limits[] = {
      {255, {5000, 0, 0}, {20000, 0}, 0xFFFF, true},
      {0, {0, -5000, 0}, {0, -20000}, 0, false},
      {17, {2886, -2886, 2886}, {14142, 14142}, 1, true},  // diagonals just inside both limits
  };
  for (const CommandWire& command : limits) {
    can_frame force;
    can_frame torque;
    encode_command(command, force, torque);
    CHECK_EQUAL(FrameEffect::HalfHeld, device.accept(force).effect);
    CHECK_EQUAL(FrameEffect::Completed, device.accept(torque).effect);
    check_same_command(command, device.latest_command());
  }
  CHECK_EQUAL(0U, device.rejections().total());
}

TEST(CanCodec, TheHostRefusesAndCountsEveryKindOfBadFrameAndAppliesNone) {
  HostFrameAssembler host(stencil::board::sherline_suzuki::kCentredDeviceRange);
  can_frame good_a;
  can_frame good_b;
  CHECK_TRUE(encode_pose(PoseWire{1, {1000, 2000, 3000}, {10, 20}}, good_a, good_b));
  CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(good_a).effect);
  CHECK_EQUAL(FrameEffect::Completed, host.accept(good_b).effect);
  const PoseWire applied = host.latest_pose();

  can_frame pose_a;
  can_frame pose_b;
  CHECK_TRUE(encode_pose(PoseWire{2, {-1000, -2000, -3000}, {-10, -20}}, pose_a, pose_b));
  can_frame short_b = pose_b;
  short_b.len = 7;
  can_frame empty_a = pose_a;
  empty_a.len = 0;
  can_frame extended_a = pose_a;
  extended_a.can_id = kPoseAId | CAN_EFF_FLAG;
  can_frame remote_b = pose_b;
  remote_b.can_id = kPoseBId | CAN_RTR_FLAG;
  can_frame reserved_a = pose_a;
  reserved_a.data[7] = 1;
  can_frame other_counter_b = pose_b;
  other_counter_b.data[0] = 3;
  can_frame status;
  encode_status(StatusWire{2, 0, 7}, status);
  status.data[7] = 0x80;

  struct Case {
    const can_frame* first;  // may be null
    can_frame second;
    FrameRejection expected;
  };
  const Case cases[] = {
      {&pose_a, short_b, FrameRejection::WrongDlc},
      {nullptr, empty_a, FrameRejection::WrongDlc},
      {nullptr, frame_of(0x123, {2, 0, 0, 0, 0, 0, 0, 0}), FrameRejection::UnknownId},
      {nullptr, frame_of(kForceId, {2, 0, 0, 0, 0, 0, 0, 0}), FrameRejection::UnknownId},  // the host's own
      {nullptr, extended_a, FrameRejection::UnknownId},
      {&pose_a, remote_b, FrameRejection::UnknownId},
      {nullptr, reserved_a, FrameRejection::ReservedNotZero},
      {nullptr, status, FrameRejection::ReservedNotZero},
      {&pose_a, other_counter_b, FrameRejection::HalvesDisagree},
      {nullptr, pose_b, FrameRejection::UnpairedHalf},
  };
  for (const Case& bad : cases) {
    if (bad.first != nullptr) CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(*bad.first).effect);
    const FrameResult result = host.accept(bad.second);
    CHECK_EQUAL(FrameEffect::Rejected, result.effect);
    CHECK_EQUAL(bad.expected, result.rejection);
    // The waiting half is never completed by a later good-looking second half.
    if (bad.first != nullptr && bad.expected != FrameRejection::WrongDlc && bad.expected != FrameRejection::UnknownId) {
      CHECK_EQUAL(FrameEffect::Rejected, host.accept(pose_b).effect);
    }
    check_same_pose(applied, host.latest_pose());
  }
  // A first half replaced before its partner came: the old one is refused, the new one pairs.
  can_frame newer_a = pose_a;
  newer_a.data[0] = 3;
  CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(newer_a).effect);
  CHECK_EQUAL(FrameEffect::HalfHeld, host.accept(pose_a).effect);
  CHECK_EQUAL(FrameEffect::Completed, host.accept(pose_b).effect);

  CHECK_EQUAL(2U, host.rejections().of(FrameRejection::WrongDlc));
  CHECK_EQUAL(4U, host.rejections().of(FrameRejection::UnknownId));
  CHECK_EQUAL(2U, host.rejections().of(FrameRejection::ReservedNotZero));
  CHECK_EQUAL(1U, host.rejections().of(FrameRejection::HalvesDisagree));
  // First halves replaced while waiting (three), the second half that followed the wrong-counter
  // pair, and the second half alone.
  CHECK_EQUAL(5U, host.rejections().of(FrameRejection::UnpairedHalf));
  CHECK_EQUAL(0U, host.rejections().of(FrameRejection::OutOfRange));
  CHECK_FALSE(host.has_status());
}

TEST(CanCodec, TheDeviceRefusesAndCountsEveryKindOfBadFrameAndAppliesNone) {
  DeviceFrameAssembler device;
  can_frame force;
  can_frame torque;
  encode_command(CommandWire{1, {100, 200, 300}, {10, 20}, 1, true}, force, torque);
  CHECK_EQUAL(FrameEffect::HalfHeld, device.accept(force).effect);
  CHECK_EQUAL(FrameEffect::Completed, device.accept(torque).effect);
  const CommandWire applied = device.latest_command();

  auto refused = [&](const CommandWire& command, FrameRejection expected) {
    can_frame bad_force;
    can_frame bad_torque;
    encode_command(command, bad_force, bad_torque);
    CHECK_EQUAL(FrameEffect::HalfHeld, device.accept(bad_force).effect);
    const FrameResult result = device.accept(bad_torque);
    CHECK_EQUAL(FrameEffect::Rejected, result.effect);
    CHECK_EQUAL(expected, result.rejection);
    check_same_command(applied, device.latest_command());
  };
  refused(CommandWire{2, {5001, 0, 0}, {0, 0}, 2, true}, FrameRejection::OutOfRange);
  refused(CommandWire{3, {3000, 4001, 0}, {0, 0}, 3, true}, FrameRejection::OutOfRange);  // 5000.8 mN
  refused(CommandWire{4, {0, 0, 0}, {0, -20001}, 4, true}, FrameRejection::OutOfRange);
  refused(CommandWire{5, {0, 0, 0}, {14143, 14143}, 5, true}, FrameRejection::OutOfRange);
  CHECK_EQUAL(4U, device.rejections().of(FrameRejection::OutOfRange));

  encode_command(CommandWire{6, {1, 1, 1}, {1, 1}, 6, true}, force, torque);
  can_frame flags_force = force;
  flags_force.data[7] = 0x03;  // enable plus an unknown bit
  can_frame reserved_torque = torque;
  reserved_torque.data[7] = 0x01;
  can_frame other_counter_torque = torque;
  other_counter_torque.data[0] = 7;
  can_frame long_force = force;
  long_force.len = 9;

  CHECK_EQUAL(FrameRejection::ReservedNotZero, device.accept(flags_force).rejection);
  CHECK_EQUAL(FrameRejection::UnpairedHalf, device.accept(torque).rejection);
  CHECK_EQUAL(FrameEffect::HalfHeld, device.accept(force).effect);
  CHECK_EQUAL(FrameRejection::ReservedNotZero, device.accept(reserved_torque).rejection);
  CHECK_EQUAL(FrameEffect::HalfHeld, device.accept(force).effect);
  CHECK_EQUAL(FrameRejection::HalvesDisagree, device.accept(other_counter_torque).rejection);
  CHECK_EQUAL(FrameRejection::WrongDlc, device.accept(long_force).rejection);
  CHECK_EQUAL(FrameRejection::UnknownId, device.accept(frame_of(kPoseAId, {1, 0, 0, 0, 0, 0, 0, 0})).rejection);
  CHECK_EQUAL(FrameRejection::UnknownId, device.accept(frame_of(0x7FF, {1, 0, 0, 0, 0, 0, 0, 0})).rejection);
  check_same_command(applied, device.latest_command());

  CHECK_EQUAL(2U, device.rejections().of(FrameRejection::ReservedNotZero));
  CHECK_EQUAL(1U, device.rejections().of(FrameRejection::UnpairedHalf));
  CHECK_EQUAL(1U, device.rejections().of(FrameRejection::HalvesDisagree));
  CHECK_EQUAL(1U, device.rejections().of(FrameRejection::WrongDlc));
  CHECK_EQUAL(2U, device.rejections().of(FrameRejection::UnknownId));
  CHECK_EQUAL(11U, device.rejections().total());
}
