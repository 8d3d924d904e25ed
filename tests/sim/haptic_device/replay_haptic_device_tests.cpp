// ReplayHapticDevice: each read gives back exactly what the recorded cycle read (a fresh sample, a
// stale read, a refusal, a fault), latching the first fault as a live backend would; commands are kept.
#include "firmware/core/control/cycle_messages.hpp"
#include "sim/haptic_device/replay_haptic_device.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using hal::ReadStatus;

namespace {

control::JournalRecord recorded(ReadStatus status, HapticFault reason) {
  control::JournalRecord record{};
  record.device_mm[0] = 1.5;
  record.device_mm[1] = -2.25;
  record.device_mm[2] = 3.0;
  record.angles_rad[0] = 0.125;
  record.angles_rad[1] = -0.5;
  record.sample_counter = 41;
  record.status_bits = 0x0102;
  record.read_status = status;
  record.read_reason = reason;
  return record;
}

}  // namespace

TEST_GROUP(ReplayHapticDevice) {
  sim::ReplayHapticDevice replay;
  hal::HapticSample sample{{9.0, 9.0, 9.0}, {9.0, 9.0}, 9, 9, 9};
};

TEST(ReplayHapticDevice, AFreshCycleGivesItsSampleBackFieldForField) {
  replay.set(recorded(ReadStatus::Fresh, HapticFault::None));
  const hal::ReadResult result = replay.read_sample(0, sample);
  CHECK_TRUE(result.status == ReadStatus::Fresh);
  DOUBLES_EQUAL(1.5, sample.position_mm[0], 0.0);
  DOUBLES_EQUAL(-2.25, sample.position_mm[1], 0.0);
  DOUBLES_EQUAL(3.0, sample.position_mm[2], 0.0);
  DOUBLES_EQUAL(0.125, sample.angles_rad[0], 0.0);
  DOUBLES_EQUAL(-0.5, sample.angles_rad[1], 0.0);
  LONGS_EQUAL(41, sample.sample_counter);
  LONGS_EQUAL(0x0102, sample.status_bits);
  LONGS_EQUAL(41, sample.device_heartbeat);  // the journal keeps no heartbeat: it moves with the counter
}

TEST(ReplayHapticDevice, AStaleOrRefusedCycleLeavesTheSampleUntouched) {
  replay.set(recorded(ReadStatus::Stale, HapticFault::None));
  CHECK_TRUE(replay.read_sample(0, sample).status == ReadStatus::Stale);
  replay.set(recorded(ReadStatus::Rejected, HapticFault::SampleOutOfRange));
  const hal::ReadResult refused = replay.read_sample(0, sample);
  CHECK_TRUE(refused.status == ReadStatus::Rejected);
  CHECK_TRUE(refused.reason == HapticFault::SampleOutOfRange);
  LONGS_EQUAL(9, sample.sample_counter);
  DOUBLES_EQUAL(9.0, sample.position_mm[0], 0.0);
  CHECK_TRUE(replay.latched_fault() == HapticFault::None);  // a refusal is not a fault
}

TEST(ReplayHapticDevice, TheFirstRecordedFaultIsLatchedUntilCleared) {
  replay.set(recorded(ReadStatus::Fault, HapticFault::DeviceHeartbeatLost));
  CHECK_TRUE(replay.read_sample(0, sample).reason == HapticFault::DeviceHeartbeatLost);
  replay.set(recorded(ReadStatus::Fault, HapticFault::TransportError));
  CHECK_TRUE(replay.read_sample(0, sample).reason == HapticFault::TransportError);
  CHECK_TRUE(replay.latched_fault() == HapticFault::DeviceHeartbeatLost);
  replay.clear_fault();
  CHECK_TRUE(replay.latched_fault() == HapticFault::None);
}

TEST(ReplayHapticDevice, CommandsAreTakenAndKept) {
  const hal::HapticCommand command{{0.5, -1.0, 2.0}, {3.0, 4.0}, 77, true};
  const hal::WriteResult result = replay.write_command(command);
  CHECK_TRUE(result.status == hal::WriteStatus::Written);
  LONGS_EQUAL(77, replay.rendered().cycle_counter);
  DOUBLES_EQUAL(2.0, replay.rendered().force_n[2], 0.0);
  CHECK_TRUE(replay.rendered().enable);
  CHECK_TRUE(replay.link_state() == hal::HapticLinkState::Connected);
}
