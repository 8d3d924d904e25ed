// The simulated CAN bus: wire time at the bitrate, arbitration by identifier, bounded queues that drop
// and count, error frames and bus-off; and the haptic exchange over it at 500 kbit/s and at 1 Mbit/s.
#include "board/sherline_suzuki/rig_facts.hpp"
#include "sim/haptic_device/simulated_can_bus.hpp"

#include <linux/can/error.h>

#include <cstdio>
#include <cstring>

#include "hal/socketcan/can_bus_load.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "hal/socketcan/can_error_frames.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/clock/virtual_clock.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"
#include "tests/hal/socketcan/can_strings.hpp"
#include "tests/sim/haptic_device/counter_pose.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace can = hal::socketcan;
using can::TransferStatus;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

can_frame status_frame(std::uint8_t counter) {
  can_frame frame;
  can::encode_status(can::StatusWire{counter, 1, counter}, frame);
  return frame;
}

can_frame force_frame(std::uint8_t counter) {
  can_frame force;
  can_frame torque;
  can::encode_command(can::CommandWire{counter, {1, 2, 3}, {4, 5}, counter, true}, force, torque);
  return force;
}

hal::MonotonicNs wire_ns(const can_frame& frame, std::uint64_t bitrate_bps) {
  return hal::MonotonicNs{can::classic_frame_bits(frame)} * 1'000'000'000 / static_cast<hal::MonotonicNs>(bitrate_bps);
}

// The host's backend and the simulated device on the two nodes of one bus, on one virtual clock.
struct HapticBus {
  sim::VirtualClock clock;
  sim::SimulatedCanBus bus;
  sim::CanDeviceLink link{bus.device()};
  sim::SimulatedHapticDevice device{link, test::counter_pose};
  can::SocketCanHapticDevice host{&bus.host(), stencil::board::sherline_suzuki::kCentredDeviceRange};

  explicit HapticBus(const sim::CanBusConfig& config) : bus(clock, config) {}

  struct Run {
    int fresh_reads;
    int fresh_with_the_last_periods_pose;  // the pose the device sent one period before the read
  };

  // Each millisecond as on the rig: the device takes the last command and sends its frames, the host
  // reads (the frames that have crossed the wire by now) and sends its command.
  Run run(int periods) {
    Run result{0, 0};
    for (int ms = 1; ms <= periods; ++ms) {
      clock.sleep_until_ns(ms * kMs);
      device.step(ms * kMs);
      hal::HapticSample sample{};
      if (host.read_sample(ms * kMs, sample).status == hal::ReadStatus::Fresh) {
        ++result.fresh_reads;
        result.fresh_with_the_last_periods_pose += sample.sample_counter == static_cast<std::uint32_t>(ms - 1) ? 1 : 0;
      }
      static_cast<void>(host.write_command(hal::HapticCommand{{0.0, 0.0, 1.0}, {0.0, 0.0}, static_cast<std::uint32_t>(ms), true}));
    }
    return result;
  }
};

}  // namespace

TEST_GROUP(SimulatedCanBus) {
  sim::VirtualClock clock;
};

TEST(SimulatedCanBus, AFrameArrivesWhenItsLastBitHasCrossedTheWireAtTheBitrate) {
  sim::SimulatedCanBus bus(clock, {500'000});
  const can_frame sent = status_frame(7);
  CHECK_EQUAL(TransferStatus::Done, bus.device().send(sent));
  const hal::MonotonicNs on_the_wire = wire_ns(sent, 500'000);  // 2 us a bit
  CHECK_TRUE(on_the_wire >= 111 * 2000);
  CHECK_TRUE(on_the_wire <= 135 * 2000);

  can_frame received{};
  CHECK_EQUAL(TransferStatus::WouldBlock, bus.host().receive(received));
  clock.advance_ns(on_the_wire - 1);
  CHECK_EQUAL(TransferStatus::WouldBlock, bus.host().receive(received));
  clock.advance_ns(1);
  CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
  MEMCMP_EQUAL(&sent, &received, sizeof sent);
  CHECK_EQUAL(TransferStatus::WouldBlock, bus.device().receive(received));  // a node does not hear itself

  const sim::CanBusCounters& counters = bus.counters();
  CHECK_EQUAL(1U, counters.frames_carried);
  CHECK_EQUAL(static_cast<std::uint64_t>(can::classic_frame_bits(sent)), counters.bits_carried);
  CHECK_EQUAL(on_the_wire, counters.max_latency_ns);
  CHECK_EQUAL(0U, counters.frames_late);
}

TEST(SimulatedCanBus, TheLowestIdentifierWinsTheBusWhenItGoesIdle) {
  sim::SimulatedCanBus bus(clock, {1'000'000});
  can_frame pose_a;
  can_frame pose_b;
  CHECK_TRUE(can::encode_pose(can::PoseWire{1, {1, 2, 3}, {4, 5}}, pose_a, pose_b));
  const can_frame status = status_frame(1);
  const can_frame force = force_frame(1);
  // The device's status takes the idle bus; then its PoseA and the host's Force wait side by side.
  CHECK_EQUAL(TransferStatus::Done, bus.device().send(status));
  CHECK_EQUAL(TransferStatus::Done, bus.device().send(pose_a));
  CHECK_EQUAL(TransferStatus::Done, bus.host().send(force));

  const hal::MonotonicNs force_done = wire_ns(status, 1'000'000) + wire_ns(force, 1'000'000);
  const hal::MonotonicNs pose_done = force_done + wire_ns(pose_a, 1'000'000);
  can_frame received{};
  clock.sleep_until_ns(force_done);
  CHECK_EQUAL(TransferStatus::Done, bus.device().receive(received));
  CHECK_EQUAL(can::kForceId, received.can_id);
  CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
  CHECK_EQUAL(can::kStatusId, received.can_id);
  CHECK_EQUAL(TransferStatus::WouldBlock, bus.host().receive(received));
  clock.sleep_until_ns(pose_done);
  CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
  CHECK_EQUAL(can::kPoseAId, received.can_id);
}

TEST(SimulatedCanBus, At500KbitAPeriodsHapticFramesDoNotFitAndArriveLateOrNotAtAll) {
  HapticBus rig({500'000});
  const HapticBus::Run run = rig.run(1000);
  const sim::CanBusCounters counters = rig.bus.counters();
  std::printf("\n  simulated bus at 500 kbit/s, 1000 ms of haptic frames: %llu frames carried, %llu late, "
              "%llu refused by the device's full transmit queue, longest %.2f ms; %d of 999 reads had the last "
              "period's pose\n",
              static_cast<unsigned long long>(counters.frames_carried), static_cast<unsigned long long>(counters.frames_late),
              static_cast<unsigned long long>(counters.device.transmit_refused),
              static_cast<double>(counters.max_latency_ns) / 1e6, run.fresh_with_the_last_periods_pose);
  CHECK_TRUE(counters.frames_late > 0);
  CHECK_TRUE(counters.max_latency_ns > kMs);
  // The device's frames lose arbitration to the host's and pile up in its transmit queue: the
  // queue refuses the overflow, and the device counts what it could not send.
  CHECK_TRUE(counters.device.transmit_refused > 0);
  CHECK_EQUAL(counters.device.transmit_refused, rig.link.frames_dropped());
  CHECK_TRUE(run.fresh_with_the_last_periods_pose < 900);
  // The bus was busy the whole time: it carried no more than 500 bits a millisecond.
  CHECK_TRUE(counters.bits_carried <= 500U * 1000U);
  CHECK_TRUE(counters.bits_carried > 490U * 1000U);

  // The same traffic on the same clock: the same timing, to the nanosecond.
  HapticBus again({500'000});
  static_cast<void>(again.run(1000));
  CHECK_EQUAL(counters.frames_carried, again.bus.counters().frames_carried);
  CHECK_EQUAL(counters.frames_late, again.bus.counters().frames_late);
  CHECK_EQUAL(counters.max_latency_ns, again.bus.counters().max_latency_ns);
  CHECK_EQUAL(counters.device.transmit_refused, again.bus.counters().device.transmit_refused);
}

TEST(SimulatedCanBus, At1MbitEveryPeriodsFramesArriveWithinThePeriod) {
  HapticBus rig({1'000'000});
  const HapticBus::Run run = rig.run(1000);
  const sim::CanBusCounters counters = rig.bus.counters();
  std::printf("\n  simulated bus at 1 Mbit/s, 1000 ms of haptic frames: %llu frames carried, %llu late, longest %.3f ms, "
              "%.1f %% of the bus used\n",
              static_cast<unsigned long long>(counters.frames_carried), static_cast<unsigned long long>(counters.frames_late),
              static_cast<double>(counters.max_latency_ns) / 1e6, static_cast<double>(counters.bits_carried) / 999e3 * 100.0);
  CHECK_EQUAL(0U, counters.frames_late);
  CHECK_TRUE(counters.max_latency_ns < kMs);
  CHECK_EQUAL(0U, counters.device.transmit_refused);
  CHECK_EQUAL(0U, counters.host.transmit_refused);
  CHECK_EQUAL(0U, counters.host.receive_dropped);
  CHECK_EQUAL(0U, rig.link.frames_dropped());
  CHECK_EQUAL(5U * 999U, counters.frames_carried);  // the last period's frames are still on their way
  // From the second millisecond on, every read gives the pose the device sent one period before.
  CHECK_EQUAL(999, run.fresh_reads);
  CHECK_EQUAL(999, run.fresh_with_the_last_periods_pose);
  CHECK_EQUAL(999U, rig.device.output().commands_accepted);
}

TEST(SimulatedCanBus, AFullReceiveQueueDropsTheNewestFramesAndCountsThem) {
  sim::CanBusConfig config{1'000'000};
  config.receive_queue_frames = 16;
  sim::SimulatedCanBus bus(clock, config);
  sim::CanDeviceLink link(bus.device());
  sim::SimulatedHapticDevice device(link, test::counter_pose);
  for (int ms = 1; ms <= 20; ++ms) {  // 60 frames, nobody reading
    clock.sleep_until_ns(ms * kMs);
    device.step(ms * kMs);
  }
  clock.advance_ns(kMs);
  CHECK_EQUAL(60U, bus.counters().frames_carried);
  CHECK_EQUAL(44U, bus.counters().host.receive_dropped);
  CHECK_EQUAL(0U, link.frames_dropped());  // the sender never knows

  // What waits is the oldest: the first five periods' frames and the sixth's PoseA.
  can_frame received{};
  for (int index = 0; index < 16; ++index) {
    CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
    CHECK_EQUAL(can::kDeviceFrameIds[index % 3], received.can_id);
    CHECK_EQUAL(index / 3 + 1, received.data[0]);
  }
  CHECK_EQUAL(TransferStatus::WouldBlock, bus.host().receive(received));
}

TEST(SimulatedCanBus, ABusOffNodeReportsItHearsNothingAndCarriesOnAfterARestart) {
  sim::SimulatedCanBus bus(clock, {1'000'000});
  bus.go_bus_off(sim::CanNode::Host);
  CHECK_TRUE(bus.bus_off(sim::CanNode::Host));
  can_frame received{};
  CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
  CHECK_EQUAL(CAN_ERR_FLAG | CAN_ERR_BUSOFF, received.can_id);

  CHECK_EQUAL(TransferStatus::Done, bus.device().send(status_frame(1)));
  clock.advance_ns(kMs);
  CHECK_EQUAL(TransferStatus::WouldBlock, bus.host().receive(received));
  CHECK_EQUAL(1U, bus.counters().host.lost_to_bus_off);
  CHECK_EQUAL(1U, bus.counters().host.error_frames);

  bus.restart(sim::CanNode::Host);
  CHECK_FALSE(bus.bus_off(sim::CanNode::Host));
  CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
  CHECK_EQUAL(CAN_ERR_FLAG | CAN_ERR_RESTARTED, received.can_id);
  CHECK_EQUAL(TransferStatus::Done, bus.device().send(status_frame(2)));
  clock.advance_ns(kMs);
  CHECK_EQUAL(TransferStatus::Done, bus.host().receive(received));
  CHECK_EQUAL(can::kStatusId, received.can_id);
  CHECK_EQUAL(2, received.data[0]);
}

TEST(SimulatedCanBus, ABusOffOnTheWayStopsTheHostsLinkWithItsReason) {
  HapticBus rig({1'000'000});
  static_cast<void>(rig.run(10));
  CHECK_EQUAL(hal::HapticLinkState::Connected, rig.host.link_state());
  rig.bus.go_bus_off(sim::CanNode::Host);
  hal::HapticSample sample{};
  const hal::ReadResult read = rig.host.read_sample(11 * kMs, sample);
  CHECK_EQUAL(hal::ReadStatus::Fault, read.status);
  CHECK_EQUAL(hal::HapticFault::TransportError, rig.host.latched_fault());
  CHECK_EQUAL(can::CanBusError::BusOff, rig.host.bus_error());
  CHECK_EQUAL(hal::HapticLinkState::Disconnected, rig.host.link_state());
}
