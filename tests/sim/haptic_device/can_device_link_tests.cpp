// CanDeviceLink over a socket pair, the host's end read and written with the codec: what publish()
// puts on the bus (units, int24 saturation, the babbling fault, dropped frames) and what poll() takes
// (the newest complete command in physical units, refusals, nothing).
#include <sys/socket.h>

#include <cmath>
#include <cstdint>

#include "hal/socketcan/can_codec.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "sim/haptic_device/can_device_link.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace can = hal::socketcan;

namespace {

// A host range wide enough that the host's assembler never refuses what the wire can carry.
constexpr hal::HapticRange kWide{{1e6, 1e6, 1e6}, 10.0, 10.0, 1e6, {0.0, 0.0, 0.0}};

struct SocketPair {
  int fds[2] = {-1, -1};
  SocketPair() { CHECK_EQUAL(0, ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds)); }
};

// A channel whose queue is always full.
struct FullChannel final : can::CanChannel {
  can::TransferStatus receive(can_frame&) override { return can::TransferStatus::WouldBlock; }
  can::TransferStatus send(const can_frame&) override { return can::TransferStatus::WouldBlock; }
};

can::CommandWire command(std::uint8_t counter, std::int16_t fz_mn, std::uint16_t heartbeat) {
  return can::CommandWire{counter, {100, -200, fz_mn}, {300, -400}, heartbeat, true};
}

}  // namespace

TEST_GROUP(CanDeviceLink) {
  SocketPair sockets;
  can::FdCanChannel host{sockets.fds[0]};
  can::FdCanChannel device{sockets.fds[1]};
  sim::CanDeviceLink link{device};
  can::HostFrameAssembler assembler{kWide};

  // Feeds every frame waiting at the host to the assembler; how many completed a pose.
  int host_reads() {
    int poses = 0;
    can_frame frame;
    while (host.receive(frame) == can::TransferStatus::Done) {
      if (assembler.accept(frame).effect == can::FrameEffect::Completed) ++poses;
    }
    return poses;
  }
  void send(const can::CommandWire& wire) {
    can_frame force;
    can_frame torque;
    can::encode_command(wire, force, torque);
    CHECK_TRUE(host.send(force) == can::TransferStatus::Done);
    CHECK_TRUE(host.send(torque) == can::TransferStatus::Done);
  }
};

TEST(CanDeviceLink, APublishedSampleArrivesInMicrometresAndHundredMicroradiansWithItsStatus) {
  link.publish(hal::HapticSample{{1.2344, -5.0, 0.0006}, {0.01234, -0.5}, 0x1FF, 0x12345, 77});
  LONGS_EQUAL(1, host_reads());
  const can::PoseWire& pose = assembler.latest_pose();
  LONGS_EQUAL(0xFF, pose.counter);  // the counter's low byte
  LONGS_EQUAL(1234, pose.position_um[0]);
  LONGS_EQUAL(-5000, pose.position_um[1]);
  LONGS_EQUAL(1, pose.position_um[2]);
  LONGS_EQUAL(123, pose.angles_100urad[0]);
  LONGS_EQUAL(-5000, pose.angles_100urad[1]);
  CHECK_TRUE(assembler.has_status());
  LONGS_EQUAL(0x2345, assembler.latest_status().status_bits);  // 16 bits on the wire
  LONGS_EQUAL(77, assembler.latest_status().device_heartbeat);
}

TEST(CanDeviceLink, PositionsBeyondInt24AreSaturatedNotDropped) {
  link.publish(hal::HapticSample{{1e6, -1e6, 0.0}, {0.0, 0.0}, 1, 0, 1});
  LONGS_EQUAL(1, host_reads());
  LONGS_EQUAL(can::kInt24Max, assembler.latest_pose().position_um[0]);
  LONGS_EQUAL(can::kInt24Min, assembler.latest_pose().position_um[1]);
}

TEST(CanDeviceLink, ABabblingDeviceSendsBadPoseFramesButItsStatusStillGoes) {
  link.babble(1);
  link.publish(hal::HapticSample{{1.0, 2.0, 3.0}, {0.0, 0.0}, 5, 0, 5});
  LONGS_EQUAL(0, host_reads());
  LONGS_EQUAL(1, assembler.rejections().of(can::FrameRejection::WrongDlc));
  LONGS_EQUAL(1, assembler.rejections().of(can::FrameRejection::HalvesDisagree));
  LONGS_EQUAL(5, assembler.latest_status().device_heartbeat);
  link.publish(hal::HapticSample{{1.0, 2.0, 3.0}, {0.0, 0.0}, 6, 0, 6});  // the babble is over
  LONGS_EQUAL(1, host_reads());
}

TEST(CanDeviceLink, FramesAFullQueueWouldNotTakeAreCounted) {
  FullChannel full;
  sim::CanDeviceLink stuck{full};
  stuck.publish(hal::HapticSample{{0.0, 0.0, 0.0}, {0.0, 0.0}, 1, 0, 1});
  LONGS_EQUAL(3, stuck.frames_dropped());
}

TEST(CanDeviceLink, PollTakesTheNewestCompleteCommandInPhysicalUnits) {
  sim::DeviceCommand out{};
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::None);
  send(command(1, 1000, 10));
  send(command(2, 2500, 11));
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::New);
  DOUBLES_EQUAL(0.1, out.force_n[0], 1e-12);
  DOUBLES_EQUAL(-0.2, out.force_n[1], 1e-12);
  DOUBLES_EQUAL(2.5, out.force_n[2], 1e-12);
  DOUBLES_EQUAL(3.0, out.torque_nmm[0], 1e-12);  // 10 mN.mm units
  DOUBLES_EQUAL(-4.0, out.torque_nmm[1], 1e-12);
  LONGS_EQUAL(2, out.cycle_counter);
  LONGS_EQUAL(11, out.host_heartbeat);
  CHECK_TRUE(out.enable);
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::None);
}

TEST(CanDeviceLink, ACommandBeyondTheDevicesLimitsIsRefusedAndNotApplied) {
  sim::DeviceCommand out{{7.0, 7.0, 7.0}, {7.0, 7.0}, 7, 7, false};
  send(command(1, static_cast<std::int16_t>(can::kForceLimitMn + 1000), 1));
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::Refused);
  DOUBLES_EQUAL(7.0, out.force_n[2], 0.0);
  CHECK_TRUE(link.rejections().total() > 0);
}
