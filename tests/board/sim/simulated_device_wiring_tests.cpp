// The simulated device as the cycle sees it (board/sim/simulated_device_wiring): in process, the
// handle's position each device millisecond as a fresh sample, the force the host writes as what the
// device renders; and the device's side of each injected fault (frozen: no sample; NaN: refused as
// not finite; a jump: one sample 100 mm off; its own fault: the status bit). Over the PIO window and
// the CAN socketpair the same sample crosses the real backends' code. Every fault over every
// transport in a whole job: the e2e cases sim_fault_device_frozen_over_pio, _over_can and the rest.
#include <string>

#include <Eigen/Core>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/simulated_device_wiring.hpp"
#include "sim/operator/operator_script.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

struct Device {
  stencil::sim::OperatorHand hand;
  std::string error;
  SimulatedDeviceWiring wiring;
  hal::MonotonicNs now = 0;
  explicit Device(HapticTransport transport) : wiring(transport, board::sherline_suzuki::kDeviceRange, hand, error) {
    hand.handle_mm = Eigen::Vector3d(250.0, 125.0, 100.0);
  }
  // One device millisecond, then the host's read.
  hal::ReadResult cycle(hal::HapticSample& sample) {
    now += kMs;
    wiring.device_cycle(hand, Eigen::Vector2d::Zero(), now);
    return wiring.host().read_sample(now, sample);
  }
};

}  // namespace

TEST_GROUP(SimulatedDeviceWiring){};

TEST(SimulatedDeviceWiring, InProcessTheHandleIsEachMillisecondsFreshSample) {
  Device d(HapticTransport::Direct);
  CHECK_TRUE(d.wiring.ready());
  hal::HapticSample sample{};
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  DOUBLES_EQUAL(250.0, sample.position_mm[0], 0.0);
  DOUBLES_EQUAL(100.0, sample.position_mm[2], 0.0);
  const std::uint32_t first = sample.sample_counter;
  d.hand.handle_mm.x() = 251.0;
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  DOUBLES_EQUAL(251.0, sample.position_mm[0], 0.0);
  CHECK_EQUAL(first + 1U, sample.sample_counter);
  CHECK(d.wiring.host().read_sample(d.now, sample).status == hal::ReadStatus::Stale);
}

TEST(SimulatedDeviceWiring, TheHostsForceIsWhatTheDeviceRenders) {
  Device d(HapticTransport::Direct);
  CHECK_TRUE(d.wiring.force_off());
  static_cast<void>(d.wiring.host().write_command({{1.0, -2.0, 0.5}, {0.0, 0.0}, 1, true}));
  CHECK_FALSE(d.wiring.force_off());
  DOUBLES_EQUAL(-2.0, d.wiring.rendered_force().y(), 0.0);
  static_cast<void>(d.wiring.host().write_command({{1.0, -2.0, 0.5}, {0.0, 0.0}, 2, false}));
  CHECK_TRUE(d.wiring.force_off());
}

TEST(SimulatedDeviceWiring, AFrozenDeviceSendsNothingMore) {
  Device d(HapticTransport::Direct);
  hal::HapticSample sample{};
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  d.wiring.inject(FaultKind::DeviceFrozen);
  CHECK(d.cycle(sample).status == hal::ReadStatus::Stale);
  CHECK(d.cycle(sample).status == hal::ReadStatus::Stale);
}

TEST(SimulatedDeviceWiring, ANanPoseIsRefusedAsNotFiniteFromThenOn) {
  Device d(HapticTransport::Direct);
  d.wiring.inject(FaultKind::PoseNan);
  hal::HapticSample sample{};
  for (int i = 0; i < 3; ++i) {
    const hal::ReadResult read = d.cycle(sample);
    CHECK(read.status == hal::ReadStatus::Rejected);
    CHECK(read.reason == hal::HapticFault::SampleNotFinite);
  }
}

TEST(SimulatedDeviceWiring, AJumpIsOneSample100MmOff) {
  Device d(HapticTransport::Direct);
  hal::HapticSample sample{};
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  d.wiring.inject(FaultKind::PoseJump);
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  DOUBLES_EQUAL(350.0, sample.position_mm[0], 0.0);
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  DOUBLES_EQUAL(250.0, sample.position_mm[0], 0.0);
}

TEST(SimulatedDeviceWiring, ADeviceFaultIsItsStatusBit) {
  Device d(HapticTransport::Direct);
  hal::HapticSample sample{};
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  CHECK_EQUAL(0U, sample.status_bits & hal::haptic_status::kDeviceFault);
  d.wiring.inject(FaultKind::DeviceFault);
  CHECK(d.cycle(sample).status == hal::ReadStatus::Fresh);
  CHECK(0U != (sample.status_bits & hal::haptic_status::kDeviceFault));
}

TEST(SimulatedDeviceWiring, OverPioAndCanTheHandleCrossesTheRealBackends) {
  for (const HapticTransport transport : {HapticTransport::Pio, HapticTransport::Can}) {
    Device d(transport);
    CHECK_TEXT(d.wiring.ready(), d.error.c_str());
    CHECK(d.wiring.simulated() != nullptr);
    hal::HapticSample sample{};
    bool fresh = false;
    for (int i = 0; i < 20 && !fresh; ++i) {
      fresh = d.cycle(sample).status == hal::ReadStatus::Fresh;
    }
    CHECK_TRUE(fresh);
    DOUBLES_EQUAL(250.0, sample.position_mm[0], 0.01);
    DOUBLES_EQUAL(125.0, sample.position_mm[1], 0.01);
  }
}
