// The SocketCAN backend's own behaviour, beyond the HapticDevice contract that
// tests/hal/haptic_device_tests.cpp runs on every backend (fresh, stale, lost, range,
// clamping, torn poses): the 8-bit wire counter extended, every kind of bad frame, error frames
// (bus-off, overflow, recovery), a backlog at the first read, torque quantisation, a full or closed
// socket, no channel, the time of one cycle, all end to end through a SOCK_SEQPACKET socket pair
// carrying struct can_frame (a vcan interface cannot be created here) against the simulated device;
// and against a real vcan0 where one exists.
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <linux/can/error.h>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/socketcan/can_error_frames.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"
#include "tests/hal/socketcan/can_strings.hpp"
#include "tests/sim/haptic_device/counter_pose.hpp"
#include "tests/support/haptic_test_values.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using hal::ReadStatus;
using hal::WriteStatus;
using test::command_of;
using test::marker_sample;
namespace can = hal::socketcan;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

}  // namespace

TEST_GROUP(SocketCanHapticDevice) {
  std::unique_ptr<can::FdCanChannel> host_channel;
  std::unique_ptr<can::FdCanChannel> device_channel;
  std::unique_ptr<sim::CanDeviceLink> device_link;
  std::unique_ptr<sim::SimulatedHapticDevice> device;
  std::unique_ptr<can::SocketCanHapticDevice> host;

  void setup() override {
    int fds[2];
    CHECK_EQUAL(0, ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds));
    host_channel = std::make_unique<can::FdCanChannel>(fds[0]);
    device_channel = std::make_unique<can::FdCanChannel>(fds[1]);
    device_link = std::make_unique<sim::CanDeviceLink>(*device_channel);
    device = std::make_unique<sim::SimulatedHapticDevice>(*device_link, test::counter_pose);
    host = std::make_unique<can::SocketCanHapticDevice>(host_channel.get(), stencil::board::sherline_suzuki::kCentredDeviceRange);
  }

  void inject(const can_frame& frame) { CHECK_EQUAL(can::TransferStatus::Done, device_channel->send(frame)); }
};

TEST(SocketCanHapticDevice, ExtendsThe8BitWireCounterAcrossItsWrap) {
  hal::HapticSample sample{};
  for (std::uint32_t k = 1; k <= 600; ++k) {
    device->step(static_cast<hal::MonotonicNs>(k) * kMs);
    if (k % 3 == 0) continue;  // a host that misses a cycle now and then still counts right
    CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(static_cast<hal::MonotonicNs>(k) * kMs, sample).status);
    CHECK_EQUAL(k, sample.sample_counter);
    CHECK_TRUE(test::consistent_with_counter(sample));
  }
}

TEST(SocketCanHapticDevice, BadFramesOnTheWireAreRefusedCountedAndNeverApplied) {
  device->step(1 * kMs);
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(1 * kMs, sample).status);
  const hal::HapticSample applied = sample;

  can_frame pose_a;
  can_frame pose_b;
  CHECK_TRUE(can::encode_pose(can::PoseWire{2, {5000, 5000, 5000}, {0, 0}}, pose_a, pose_b));
  can_frame short_a = pose_a;
  short_a.len = 6;
  can_frame unknown = pose_a;
  unknown.can_id = 0x42;
  can_frame other_counter_b = pose_b;
  other_counter_b.data[0] = 9;
  inject(short_a);
  inject(unknown);
  inject(pose_a);
  inject(other_counter_b);
  // A message that is not one can_frame at all.
  const char garbage[10] = {};
  CHECK_EQUAL(10, ::send(device_channel->fd(), garbage, sizeof garbage, 0));

  sample = marker_sample();
  const hal::ReadResult refused = host->read_sample(2 * kMs, sample);
  CHECK_EQUAL(ReadStatus::Rejected, refused.status);
  CHECK_EQUAL(HapticFault::BadFrame, refused.reason);
  CHECK_EQUAL(0xDEADU, sample.sample_counter);
  CHECK_EQUAL(1U, host->rejections().of(can::FrameRejection::WrongDlc));
  CHECK_EQUAL(1U, host->rejections().of(can::FrameRejection::UnknownId));
  CHECK_EQUAL(1U, host->rejections().of(can::FrameRejection::HalvesDisagree));
  CHECK_EQUAL(1U, host->rejections().of(can::FrameRejection::WrongSize));
  CHECK_EQUAL(4U, host->counters().bad_frames);

  // The device's next pose comes through as if nothing happened.
  device->step(4 * kMs);
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(4 * kMs, sample).status);
  CHECK_EQUAL(applied.sample_counter + 1, sample.sample_counter);
  CHECK_TRUE(test::consistent_with_counter(sample));
}

TEST(SocketCanHapticDevice, ABusOffErrorFrameIsALatchedLinkFaultNamedBusOff) {
  device->step(1 * kMs);
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(1 * kMs, sample).status);
  inject(can::make_error_frame(CAN_ERR_BUSOFF));  // what the controller's driver reports
  device->step(2 * kMs);

  sample = marker_sample();
  const hal::ReadResult off = host->read_sample(2 * kMs, sample);
  CHECK_EQUAL(ReadStatus::Fault, off.status);
  CHECK_EQUAL(HapticFault::TransportError, off.reason);
  CHECK_EQUAL(0xDEADU, sample.sample_counter);
  CHECK_EQUAL(HapticFault::TransportError, host->latched_fault());
  CHECK_EQUAL(can::CanBusError::BusOff, host->bus_error());
  STRCMP_EQUAL("bus-off", can::can_bus_error_name(host->bus_error()));
  CHECK_EQUAL(hal::HapticLinkState::Disconnected, host->link_state());
  CHECK_EQUAL(1U, host->can_counters().error_frames);
  CHECK_EQUAL(0U, host->counters().bad_frames);  // an error frame is not a bad data frame

  // The bus came back: frames are read again, but the latch holds until the cycle clears it.
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(2 * kMs, sample).status);
  CHECK_EQUAL(hal::HapticLinkState::Connected, host->link_state());
  CHECK_EQUAL(HapticFault::TransportError, host->latched_fault());
  CHECK_EQUAL(can::CanBusError::BusOff, host->bus_error());
  host->clear_fault();
  CHECK_EQUAL(HapticFault::None, host->latched_fault());
  CHECK_EQUAL(can::CanBusError::None, host->bus_error());
}

TEST(SocketCanHapticDevice, AControllerThatLostFramesIsALinkFaultNamingTheOverflow) {
  inject(can::make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW));
  hal::HapticSample sample{};
  const hal::ReadResult lost = host->read_sample(1 * kMs, sample);
  CHECK_EQUAL(ReadStatus::Fault, lost.status);
  CHECK_EQUAL(HapticFault::TransportError, lost.reason);
  CHECK_EQUAL(can::CanBusError::ControllerOverflow, host->bus_error());
  // A later error keeps the first reason, like every latch.
  inject(can::make_error_frame(CAN_ERR_BUSOFF));
  CHECK_EQUAL(ReadStatus::Fault, host->read_sample(2 * kMs, sample).status);
  CHECK_EQUAL(can::CanBusError::ControllerOverflow, host->bus_error());
  CHECK_EQUAL(2U, host->can_counters().error_frames);
}

TEST(SocketCanHapticDevice, AControllerBackToErrorActiveIsCountedAndIsNoFault) {
  device->step(1 * kMs);
  inject(can::make_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE));
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(1 * kMs, sample).status);
  CHECK_EQUAL(HapticFault::None, host->latched_fault());
  CHECK_EQUAL(can::CanBusError::None, host->bus_error());
  CHECK_EQUAL(1U, host->can_counters().error_frames);
}

TEST(SocketCanHapticDevice, FramesQueuedWhileTheLinkSatUnreadAreNeverTheFirstPose) {
  // Homing: the socket is open, nobody reads it, the device sends every millisecond. Its queue fills
  // and then, as the kernel does, the newest frames are dropped: what waits is the oldest.
  constexpr int kHomingMs = 3000;
  for (int ms = 1; ms <= kHomingMs; ++ms) device->step(ms * kMs);
  CHECK_TRUE(device_link->frames_dropped() > 0);

  // The cycle starts. The first pose it is given must be the device's newest, within the controller's
  // five stale periods.
  int ms = kHomingMs;
  hal::HapticSample sample = marker_sample();
  ReadStatus status = host->read_sample(ms * kMs, sample).status;
  int reads = 1;
  while (status != ReadStatus::Fresh && reads < 5) {
    ++ms;
    device->step(ms * kMs);
    status = host->read_sample(ms * kMs, sample).status;
    ++reads;
  }
  CHECK_EQUAL(ReadStatus::Fresh, status);
  // The device's heartbeat carries all 32 bits of its cycle count (the pose's counter only 8).
  CHECK_EQUAL(static_cast<std::uint32_t>(ms), sample.device_heartbeat);
  const sim::SimulatedPose newest = test::counter_pose(static_cast<std::uint32_t>(ms), 0);
  DOUBLES_EQUAL(newest.position_mm[0], sample.position_mm[0], 1e-9);
  DOUBLES_EQUAL(newest.position_mm[2], sample.position_mm[2], 1e-9);
  CHECK_TRUE(reads <= 3);
  CHECK_TRUE(host->can_counters().frames_discarded_at_start > 100);
  CHECK_EQUAL(0U, host->counters().bad_frames);
}

// Torque goes in 10 mN.mm steps, rounded toward zero (the contract's clamping holds on top of it).
TEST(SocketCanHapticDevice, CommandsReachTheDeviceQuantisedTowardZero) {
  hal::HapticCommand command = command_of(1.5, -0.25, 0.0);
  command.torque_nmm[0] = 123.456;
  command.torque_nmm[1] = -0.019;
  CHECK_EQUAL(WriteStatus::Written, host->write_command(command).status);
  device->step(1 * kMs);
  const sim::DeviceOutput output = device->output();
  CHECK_TRUE(output.force_applied);
  DOUBLES_EQUAL(1.5, output.force_n[0], 1e-9);
  DOUBLES_EQUAL(-0.25, output.force_n[1], 1e-9);
  DOUBLES_EQUAL(123.45, output.torque_nmm[0], 1e-9);  // toward zero, 10 mN.mm steps
  DOUBLES_EQUAL(-0.01, output.torque_nmm[1], 1e-9);
  CHECK_EQUAL(7U, output.last_cycle_counter);
  CHECK_EQUAL(0U, device_link->rejections().total());
}

TEST(SocketCanHapticDevice, AFullQueueDropsTheCommandAndLatchesTheFault) {
  const can_frame filler{};
  int queued = 0;
  while (queued < 1'000'000 && host_channel->send(filler) == can::TransferStatus::Done) ++queued;
  CHECK_TRUE(queued > 0);
  CHECK_TRUE(queued < 1'000'000);
  const hal::WriteResult full = host->write_command(command_of(1.0, 0.0, 0.0));
  CHECK_EQUAL(WriteStatus::Fault, full.status);
  CHECK_EQUAL(HapticFault::TransportFull, full.reason);
  CHECK_EQUAL(HapticFault::TransportFull, host->latched_fault());
  CHECK_EQUAL(1U, host->counters().transport_errors);
}

TEST(SocketCanHapticDevice, AClosedPeerIsATransportFault) {
  device_link.reset();
  device.reset();
  device_channel.reset();
  hal::HapticSample sample{};
  const hal::ReadResult read = host->read_sample(1 * kMs, sample);
  CHECK_EQUAL(ReadStatus::Fault, read.status);
  CHECK_EQUAL(HapticFault::TransportError, read.reason);
  CHECK_EQUAL(hal::HapticLinkState::Disconnected, host->link_state());
  CHECK_EQUAL(WriteStatus::Fault, host->write_command(command_of(0.0, 0.0, 0.0)).status);
}

TEST(SocketCanHapticDevice, ABackendWithoutAChannelReportsNotOpen) {
  can::SocketCanHapticDevice closed(nullptr, stencil::board::sherline_suzuki::kCentredDeviceRange);
  CHECK_EQUAL(hal::HapticLinkState::Closed, closed.link_state());
  hal::HapticSample sample{};
  CHECK_EQUAL(HapticFault::NotOpen, closed.read_sample(0, sample).reason);
  CHECK_EQUAL(HapticFault::NotOpen, closed.write_command(command_of(0.0, 0.0, 0.0)).reason);
  CHECK_EQUAL(HapticFault::NotOpen, closed.latched_fault());
}

TEST(SocketCanHapticDevice, MeasuresTheReadAndWriteOfOneCycle) {
  constexpr int kCycles = 20000;
  std::vector<long long> durations_ns;
  durations_ns.reserve(kCycles);
  hal::HapticSample sample{};
  int fresh = 0;
  int written = 0;
  for (int cycle = 1; cycle <= kCycles; ++cycle) {
    device->step(cycle * kMs);  // the device's frames (and its reading of the last command), not timed
    const auto start = std::chrono::steady_clock::now();
    const hal::ReadResult read = host->read_sample(cycle * kMs, sample);
    const hal::WriteResult write = host->write_command(command_of(0.0001 * cycle, 0.0, 1.0));
    const auto stop = std::chrono::steady_clock::now();
    durations_ns.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
    fresh += read.status == ReadStatus::Fresh ? 1 : 0;
    written += write.status != WriteStatus::Fault ? 1 : 0;
  }
  std::nth_element(durations_ns.begin(), durations_ns.begin() + kCycles / 2, durations_ns.end());
  std::printf("\n  socketcan (socketpair): read+write of one cycle: median %lld ns over %d cycles "
              "(3 frames received, 2 sent)\n",
              durations_ns[kCycles / 2], kCycles);
  CHECK_EQUAL(kCycles, fresh);
  CHECK_EQUAL(kCycles, written);
}

TEST_GROUP(SocketCanOnVcan0) {};

// Needs a vcan0 interface (ip link add dev vcan0 type vcan; ip link set up vcan0); skipped otherwise.
TEST(SocketCanOnVcan0, PosesAndCommandsCrossARealCanInterface) {
  std::string error;
  const canid_t device_to_host[] = {can::kPoseAId, can::kPoseBId, can::kStatusId};
  const canid_t host_to_device[] = {can::kForceId, can::kTorqueId};
  const int host_fd = can::open_can_raw_socket("vcan0", device_to_host, 3, error);
  if (host_fd < 0) {
    std::printf("\n  SKIPPED SocketCanOnVcan0: %s\n", error.c_str());
    return;
  }
  can::FdCanChannel host_channel(host_fd);
  const int device_fd = can::open_can_raw_socket("vcan0", host_to_device, 2, error);
  CHECK_TEXT(device_fd >= 0, error.c_str());
  can::FdCanChannel device_channel(device_fd);
  sim::CanDeviceLink device_link(device_channel);
  sim::SimulatedHapticDevice device(device_link, test::counter_pose);
  can::SocketCanHapticDevice host(&host_channel, stencil::board::sherline_suzuki::kCentredDeviceRange);

  hal::HapticSample sample{};
  device.step(1 * kMs);
  CHECK_EQUAL(ReadStatus::Fresh, host.read_sample(1 * kMs, sample).status);
  CHECK_TRUE(test::consistent_with_counter(sample));
  CHECK_EQUAL(WriteStatus::Written, host.write_command(command_of(0.0, 1.0, 0.0)).status);
  device.step(2 * kMs);
  DOUBLES_EQUAL(1.0, device.output().force_n[1], 1e-9);
}
