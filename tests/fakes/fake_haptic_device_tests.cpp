// The fake haptic device's own tests (tests/fakes/fake_haptic_device.hpp): reads do what the test
// scripted (a fresh sample at the held pose, its counter moving by one a read, or the status and
// reason given, with `out` untouched), a scripted Fault latches until cleared, writes are recorded in
// order and can be made to fail, and the link state follows connect(). The cycle's tests trust it.
#include <cstdint>

#include "hal/haptic_device.hpp"
#include "tests/fakes/fake_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"
#include "tests/support/haptic_test_values.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using hal::ReadStatus;
using hal::WriteStatus;

TEST_GROUP(FakeHapticDevice) {
  test::FakeHapticDevice device;
  hal::HapticSample out = test::marker_sample();
};

TEST(FakeHapticDevice, ByDefaultEachReadIsFreshAtTheOriginWithTheCounterMovingByOne) {
  for (std::uint32_t read = 1; read <= 3; ++read) {
    const hal::ReadResult result = device.read_sample(0, out);
    CHECK_EQUAL(ReadStatus::Fresh, result.status);
    CHECK_EQUAL(HapticFault::None, result.reason);
    CHECK_EQUAL(read, out.sample_counter);
    DOUBLES_EQUAL(0.0, out.position_mm[0], 0.0);
  }
  CHECK_EQUAL(3U, device.reads());
  CHECK_EQUAL(hal::HapticLinkState::Connected, device.link_state());
  CHECK_EQUAL(HapticFault::None, device.latched_fault());
}

TEST(FakeHapticDevice, ReadsGiveTheHeldPoseAndStatusBits) {
  device.hold_at(1.5, -2.5, 3.5);
  device.set_status_bits(hal::haptic_status::kHostWatchdogTripped);
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  DOUBLES_EQUAL(1.5, out.position_mm[0], 0.0);
  DOUBLES_EQUAL(-2.5, out.position_mm[1], 0.0);
  DOUBLES_EQUAL(3.5, out.position_mm[2], 0.0);
  CHECK_EQUAL(hal::haptic_status::kHostWatchdogTripped, out.status_bits);
  device.hold_at(0.0, 0.0, 7.0);
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  DOUBLES_EQUAL(7.0, out.position_mm[2], 0.0);
}

TEST(FakeHapticDevice, AScriptedStatusIsGivenOnEveryReadWithOutUntouched) {
  device.give(ReadStatus::Rejected, HapticFault::SampleOutOfRange);
  for (int read = 0; read < 2; ++read) {
    const hal::ReadResult result = device.read_sample(0, out);
    CHECK_EQUAL(ReadStatus::Rejected, result.status);
    CHECK_EQUAL(HapticFault::SampleOutOfRange, result.reason);
    CHECK_EQUAL(0xDEADU, out.sample_counter);
  }
  CHECK_EQUAL(HapticFault::None, device.latched_fault());  // refused input is not latched
  device.give(ReadStatus::Stale);
  CHECK_EQUAL(ReadStatus::Stale, device.read_sample(0, out).status);
  CHECK_EQUAL(0xDEADU, out.sample_counter);

  // Fresh again: the counter carries on from where the fresh reads left it, not from the reads made.
  device.give(ReadStatus::Fresh);
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  CHECK_EQUAL(1U, out.sample_counter);
  CHECK_EQUAL(4U, device.reads());
}

TEST(FakeHapticDevice, AScriptedFaultLatchesItsReasonUntilCleared) {
  device.give(ReadStatus::Fault, HapticFault::DeviceHeartbeatLost);
  const hal::ReadResult result = device.read_sample(0, out);
  CHECK_EQUAL(ReadStatus::Fault, result.status);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, result.reason);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, device.latched_fault());
  device.give(ReadStatus::Fresh);
  CHECK_EQUAL(ReadStatus::Fresh, device.read_sample(0, out).status);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, device.latched_fault());  // held through a recovery
  device.clear_fault();
  CHECK_EQUAL(HapticFault::None, device.latched_fault());
}

TEST(FakeHapticDevice, EveryWriteIsRecordedInOrderAsGiven) {
  CHECK_TRUE(device.commands().empty());
  const hal::HapticCommand first = test::command_of(1.0, 2.0, 3.0);
  hal::HapticCommand second = test::command_of(0.0, 0.0, -9.0, false);
  second.cycle_counter = 8;
  CHECK_EQUAL(WriteStatus::Written, device.write_command(first).status);
  CHECK_EQUAL(WriteStatus::Written, device.write_command(second).status);  // 9 N: a fake does not clamp
  CHECK_EQUAL(2U, device.commands().size());
  DOUBLES_EQUAL(2.0, device.commands()[0].force_n[1], 0.0);
  CHECK_TRUE(device.commands()[0].enable);
  DOUBLES_EQUAL(-9.0, device.last_command().force_n[2], 0.0);
  CHECK_FALSE(device.last_command().enable);
  CHECK_EQUAL(8U, device.last_command().cycle_counter);
}

TEST(FakeHapticDevice, FailingWritesAreTransportFaultsLatchedAndStillRecorded) {
  device.fail_writes(true);
  const hal::WriteResult result = device.write_command(test::command_of(1.0, 0.0, 0.0));
  CHECK_EQUAL(WriteStatus::Fault, result.status);
  CHECK_EQUAL(HapticFault::TransportError, result.reason);
  CHECK_EQUAL(HapticFault::TransportError, device.latched_fault());
  CHECK_EQUAL(1U, device.commands().size());
  device.fail_writes(false);
  CHECK_EQUAL(WriteStatus::Written, device.write_command(test::command_of(1.0, 0.0, 0.0)).status);
}

TEST(FakeHapticDevice, TheLinkStateFollowsConnectAndTheCountersStayZero) {
  device.connect(false);
  CHECK_EQUAL(hal::HapticLinkState::Disconnected, device.link_state());
  device.connect(true);
  CHECK_EQUAL(hal::HapticLinkState::Connected, device.link_state());
  static_cast<void>(device.read_sample(0, out));
  const hal::HapticCounters counters = device.counters();
  CHECK_EQUAL(0U, counters.samples_accepted);  // the fake keeps none: a test that needs them uses a real backend
  CHECK_EQUAL(0U, counters.stale_reads);
}
