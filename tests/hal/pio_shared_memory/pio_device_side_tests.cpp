// The device controller's side of the shared window (hal/pio_shared_memory/pio_device_side.cpp) on a
// plain SharedWindow: the header it writes at power-up, its pose writes, and its reads of the host's
// command (new once, unchanged after, busy on a torn block, refused beyond its own limits), counted.
#include <cstdint>
#include <limits>

#include "hal/pio_shared_memory/pio_device_side.hpp"
#include "hal/pio_shared_memory/seqlock.hpp"
#include "hal/pio_shared_memory/shared_window_mapping.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace pio = hal::pio_shared_memory;

namespace {

pio::CommandWords command_words(std::int32_t fx, std::int32_t fy, std::int32_t fz, std::uint32_t heartbeat) {
  return pio::CommandWords{heartbeat, {fx, fy, fz}, {0, 0}, pio::kCommandEnableBit, heartbeat};
}

}  // namespace

// The window is a mapped memfd, as in use (a SharedWindow is cache-line aligned, which a test
// group's own allocation does not honour).
TEST_GROUP(PioDeviceSide) {
  test::WindowPair windows = test::make_device_window();
  pio::SharedWindow& window = windows.device->window();
  pio::PioDeviceSide device{window};

  // What the host side does: one seqlock write of the command block.
  void host_writes(const pio::CommandWords& words) { pio::seqlock_write(window.command, words); }
};

TEST(PioDeviceSide, InitialisingTheHeaderWritesWhatTheHostChecks) {
  STRCMP_CONTAINS("magic", pio::check_window_header(window, "w").c_str());
  device.initialise_header();
  CHECK_EQUAL(pio::kWindowMagic, window.header.magic);
  CHECK_EQUAL(pio::kLayoutVersion, window.header.layout_version);
  CHECK_EQUAL(static_cast<std::uint32_t>(pio::kWindowBytes), window.header.window_bytes);
  STRCMP_EQUAL("", pio::check_window_header(window, "w").c_str());
}

TEST(PioDeviceSide, APosePublishedIsOneWholeSeqlockWriteAndCounted) {
  const pio::PoseWords pose{5U, {1, -2, 3}, {4, -5}, 0x3U, 6U};
  device.publish_pose(pose);
  device.publish_pose(pose);
  CHECK_EQUAL(4U, window.pose.sequence);
  pio::PoseWords read{};
  CHECK_TRUE(pio::seqlock_read(window.pose, read).consistent);
  CHECK_EQUAL(5U, read.sample_counter);
  CHECK_EQUAL(-2, read.position_um[1]);
  CHECK_EQUAL(-5, read.angles_urad[1]);
  CHECK_EQUAL(0x3U, read.status_bits);
  CHECK_EQUAL(6U, read.device_heartbeat);
  CHECK_EQUAL(2U, device.counters().poses_written);
}

TEST(PioDeviceSide, ACommandIsNewOnceThenUnchangedUntilTheHostWritesAgain) {
  pio::CommandWords out = command_words(9, 9, 9, 99);
  CHECK(pio::CommandReadStatus::Unchanged == device.read_command(out));  // the host never wrote
  CHECK_EQUAL(99U, out.host_heartbeat);

  host_writes(command_words(100, -200, 300, 1));
  CHECK(pio::CommandReadStatus::New == device.read_command(out));
  CHECK_EQUAL(100, out.force_mn[0]);
  CHECK_EQUAL(-200, out.force_mn[1]);
  CHECK_EQUAL(300, out.force_mn[2]);
  CHECK_EQUAL(1U, out.host_heartbeat);
  CHECK_EQUAL(pio::kCommandEnableBit, out.flags);

  out = command_words(9, 9, 9, 99);
  CHECK(pio::CommandReadStatus::Unchanged == device.read_command(out));
  CHECK_EQUAL(99U, out.host_heartbeat);  // untouched

  host_writes(command_words(100, -200, 300, 2));  // the same numbers again: still a new command
  CHECK(pio::CommandReadStatus::New == device.read_command(out));
  CHECK_EQUAL(2U, out.host_heartbeat);
  CHECK_EQUAL(2U, device.counters().commands_accepted);
}

TEST(PioDeviceSide, ACommandTheHostIsStillWritingIsBusyAndTakenOnceFinished) {
  host_writes(command_words(1, 0, 0, 1));
  window.command.sequence += 1U;  // the host is mid-write
  pio::CommandWords out = command_words(9, 9, 9, 99);
  CHECK(pio::CommandReadStatus::Busy == device.read_command(out));
  CHECK_EQUAL(99U, out.host_heartbeat);
  CHECK_EQUAL(1U, device.counters().busy_reads);
  CHECK_EQUAL(static_cast<std::uint64_t>(pio::kSeqlockAttempts), device.counters().torn_read_retries);

  host_writes(command_words(2, 0, 0, 2));  // the host's next write completes the block
  CHECK(pio::CommandReadStatus::New == device.read_command(out));
  CHECK_EQUAL(2, out.force_mn[0]);
}

TEST(PioDeviceSide, TheDevicesOwnLimitsAreInclusiveMagnitudes) {
  CHECK_TRUE(pio::command_within_device_limits(command_words(3000, 4000, 0, 1)));  // exactly 5000 mN
  CHECK_FALSE(pio::command_within_device_limits(command_words(3000, 4000, 1, 1)));
  CHECK_FALSE(pio::command_within_device_limits(command_words(0, 0, -5001, 1)));

  pio::CommandWords torque = command_words(0, 0, 0, 1);
  torque.torque_mnmm[0] = 120000;
  torque.torque_mnmm[1] = -160000;  // exactly 200000 mN.mm
  CHECK_TRUE(pio::command_within_device_limits(torque));
  torque.torque_mnmm[1] = -160001;
  CHECK_FALSE(pio::command_within_device_limits(torque));

  // One word at the extreme of its type is refused, whatever its sign.
  CHECK_FALSE(pio::command_within_device_limits(command_words(std::numeric_limits<std::int32_t>::min(), 0, 0, 1)));
  CHECK_FALSE(pio::command_within_device_limits(command_words(0, std::numeric_limits<std::int32_t>::max(), 0, 1)));
}

// Words near the int32 limits: their squares summed in a signed 64 bits overflowed (2^62 twice is
// 2^63; undefined, in practice negative) and such a command was accepted as within 5 N. The host
// clamps before it writes, so only a broken host sends them: the device's own check is for it.
TEST(PioDeviceSide, TheSquaresOfTheLargestWordsDoNotWrapRoundToSomethingSmall) {
  constexpr std::int32_t kMost = std::numeric_limits<std::int32_t>::max();
  constexpr std::int32_t kLeast = std::numeric_limits<std::int32_t>::min();
  CHECK_FALSE(pio::command_within_device_limits(command_words(kLeast, kLeast, kMost, 1)));
  pio::CommandWords huge_torque = command_words(0, 0, 0, 1);
  huge_torque.torque_mnmm[0] = kLeast;
  huge_torque.torque_mnmm[1] = kLeast;
  CHECK_FALSE(pio::command_within_device_limits(huge_torque));
}

TEST(PioDeviceSide, UnknownFlagBitsAreRefusedEnableOffIsNot) {
  pio::CommandWords words = command_words(0, 0, 0, 1);
  words.flags = 0U;
  CHECK_TRUE(pio::command_within_device_limits(words));
  words.flags = pio::kCommandEnableBit | 0x80000000U;
  CHECK_FALSE(pio::command_within_device_limits(words));
}

TEST(PioDeviceSide, ACommandBeyondTheLimitsIsRefusedOnceCountedAndNeverHandedOut) {
  host_writes(command_words(0, 0, 5001, 1));
  pio::CommandWords out = command_words(9, 9, 9, 99);
  CHECK(pio::CommandReadStatus::OutOfRange == device.read_command(out));
  CHECK_EQUAL(99U, out.host_heartbeat);
  CHECK(pio::CommandReadStatus::Unchanged == device.read_command(out));  // refused once, not on every read
  CHECK_EQUAL(1U, device.counters().commands_out_of_range);
  CHECK_EQUAL(0U, device.counters().commands_accepted);

  host_writes(command_words(0, 0, 5000, 2));
  CHECK(pio::CommandReadStatus::New == device.read_command(out));
  CHECK_EQUAL(5000, out.force_mn[2]);
}
