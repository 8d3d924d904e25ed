// The simulated haptic device: its host-heartbeat watchdog on both wires (a frozen host never leaves
// force on the handle), re-arming, a trip kept across a host restart, freezing, its 1 kHz thread, and
// scripted trajectories. The commands go onto the wire plainly, as the contract lets any host send
// them (the backends' own arming is tested with each backend); the backends read the samples.
#include <sys/socket.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/seqlock.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "sim/haptic_device/simulated_device_thread.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"
#include "tests/sim/haptic_device/counter_pose.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::ReadStatus;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

hal::HapticCommand push(double fz, bool enable = true) { return hal::HapticCommand{{0.0, 0.0, fz}, {0.0, 0.0}, 1, enable}; }

// One host and one simulated device joined by either wire, so each watchdog test runs on both.
struct Rig {
  virtual ~Rig() = default;
  virtual hal::HapticDevice& host() = 0;
  virtual sim::SimulatedHapticDevice& device() = 0;
  // Writes the command onto the wire as given (enable included) with the host heartbeat + 1.
  virtual void send_plainly(const hal::HapticCommand& command) = 0;
  // The host program ends and a new one opens the same wire (the device and its state stay).
  virtual void restart_host() = 0;
};

struct PioRig final : Rig {
  test::WindowPair windows = test::make_device_window();
  sim::PioDeviceLink link{windows.device->window()};
  sim::SimulatedHapticDevice simulated{link, test::counter_pose};
  std::unique_ptr<hal::pio_shared_memory::PioHapticDevice> backend;
  PioRig() { restart_host(); }
  hal::HapticDevice& host() override { return *backend; }
  sim::SimulatedHapticDevice& device() override { return simulated; }
  void send_plainly(const hal::HapticCommand& command) override {
    namespace pio = hal::pio_shared_memory;
    pio::CommandBlock& block = windows.host->window().command;
    pio::CommandWords words{};
    words.cycle_counter = command.cycle_counter;
    for (int axis = 0; axis < 3; ++axis) words.force_mn[axis] = static_cast<std::int32_t>(std::lround(command.force_n[axis] * 1e3));
    for (int axis = 0; axis < 2; ++axis) {
      words.torque_mnmm[axis] = static_cast<std::int32_t>(std::lround(command.torque_nmm[axis] * 1e3));
    }
    words.flags = command.enable ? pio::kCommandEnableBit : 0U;
    words.host_heartbeat = pio::load_word(block.host_heartbeat) + 1U;  // continues the window's, as a restarted host does
    pio::seqlock_write(block, words);
  }
  void restart_host() override {
    backend.reset();
    windows.host.reset();
    test::open_host_window(windows);
    CHECK_TRUE(windows.host != nullptr);
    backend = std::make_unique<hal::pio_shared_memory::PioHapticDevice>(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange);
  }
};

struct SocketPair {
  int fds[2] = {-1, -1};
  SocketPair() { CHECK_EQUAL(0, ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds)); }
};

struct CanRig final : Rig {
  SocketPair sockets;  // first: the channels below take its two ends
  hal::socketcan::FdCanChannel host_channel{sockets.fds[0]};
  hal::socketcan::FdCanChannel device_channel{sockets.fds[1]};
  sim::CanDeviceLink link{device_channel};
  sim::SimulatedHapticDevice simulated{link, test::counter_pose};
  hal::socketcan::SocketCanHapticDevice backend{&host_channel, stencil::board::sherline_suzuki::kCentredDeviceRange};
  std::uint16_t plain_heartbeat = 0;
  hal::HapticDevice& host() override { return backend; }
  sim::SimulatedHapticDevice& device() override { return simulated; }
  void send_plainly(const hal::HapticCommand& command) override {
    namespace can = hal::socketcan;
    can::CommandWire wire{};
    wire.counter = static_cast<std::uint8_t>(command.cycle_counter & 0xFFU);
    for (int axis = 0; axis < 3; ++axis) wire.force_mn[axis] = static_cast<std::int16_t>(std::lround(command.force_n[axis] * 1e3));
    for (int axis = 0; axis < 2; ++axis) {
      wire.torque_10mnmm[axis] = static_cast<std::int16_t>(std::lround(command.torque_nmm[axis] / can::kTorqueNmmPerUnit));
    }
    wire.host_heartbeat = ++plain_heartbeat;
    wire.enable = command.enable;
    can_frame force_frame;
    can_frame torque_frame;
    can::encode_command(wire, force_frame, torque_frame);
    CHECK_TRUE(host_channel.send(force_frame) == can::TransferStatus::Done);
    CHECK_TRUE(host_channel.send(torque_frame) == can::TransferStatus::Done);
  }
  // A new program on the bus counts its heartbeat afresh (the bus keeps no host state).
  void restart_host() override { plain_heartbeat = 0; }
};

// Host and device both run each millisecond from `first_ms` to `last_ms`, the host sending `command`.
void run_together(Rig& rig, int first_ms, int last_ms, const hal::HapticCommand& command) {
  for (int ms = first_ms; ms <= last_ms; ++ms) {
    rig.send_plainly(command);
    rig.device().step(ms * kMs);
  }
}

// A host that was away finds a backlog on CAN (it drains a bounded number of frames per read): read
// until nothing new comes, keeping the newest sample.
ReadStatus read_newest(Rig& rig, hal::MonotonicNs now_ns, hal::HapticSample& sample) {
  ReadStatus newest = ReadStatus::Stale;
  for (int read = 0; read < 20; ++read) {
    const ReadStatus status = rig.host().read_sample(now_ns, sample).status;
    if (status == ReadStatus::Stale) break;
    newest = status;
  }
  return newest;
}

void check_zeroes_force_when_the_host_freezes(Rig& rig) {
  // The host's cycle reads from its start (a CAN host whose very first read finds a backlog discards
  // it: see SocketCanHapticDevice); what it finds after being away later is drained as usual.
  hal::HapticSample first{};
  CHECK_EQUAL(ReadStatus::Stale, rig.host().read_sample(0, first).status);
  run_together(rig, 1, 10, push(2.0));
  CHECK_TRUE(rig.device().output().force_applied);
  DOUBLES_EQUAL(2.0, rig.device().output().force_n[2], 1e-9);

  // The host stops at 10 ms. The device keeps driving the last command up to its watchdog time...
  const hal::MonotonicNs last_beat = 10 * kMs;
  for (hal::MonotonicNs now = last_beat + kMs; now <= last_beat + sim::kDefaultHostWatchdogNs; now += kMs) {
    rig.device().step(now);
    CHECK_TRUE(rig.device().output().force_applied);
  }
  // ...and not one millisecond after it.
  rig.device().step(last_beat + sim::kDefaultHostWatchdogNs + kMs);
  const sim::DeviceOutput output = rig.device().output();
  CHECK_FALSE(output.force_applied);
  CHECK_TRUE(output.watchdog_tripped);
  DOUBLES_EQUAL(0.0, output.force_n[2], 0.0);
  CHECK_EQUAL(1U, output.watchdog_trips);

  // The host sees the trip in the device's status bits.
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, read_newest(rig, last_beat + sim::kDefaultHostWatchdogNs + kMs, sample));
  CHECK_EQUAL(rig.device().output().samples_written, sample.sample_counter);
  CHECK_TRUE((sample.status_bits & hal::haptic_status::kHostWatchdogTripped) != 0U);
  CHECK_TRUE((sample.status_bits & hal::haptic_status::kForceApplied) == 0U);
}

void check_stays_off_after_a_trip_until_re_armed(Rig& rig) {
  run_together(rig, 1, 5, push(1.0));
  rig.device().step(40 * kMs);  // the host was away 35 ms: tripped
  CHECK_TRUE(rig.device().output().watchdog_tripped);

  // The host comes back still asking for force: the device stays at zero.
  run_together(rig, 41, 50, push(1.0));
  CHECK_FALSE(rig.device().output().force_applied);
  // Enable off re-arms; enable on then drives.
  run_together(rig, 51, 51, push(0.0, false));
  CHECK_FALSE(rig.device().output().watchdog_tripped);
  CHECK_FALSE(rig.device().output().force_applied);
  run_together(rig, 52, 52, push(1.0));
  CHECK_TRUE(rig.device().output().force_applied);
  DOUBLES_EQUAL(1.0, rig.device().output().force_n[2], 1e-9);
}

// The contract (hal/pio_shared_memory/shared_window_layout.hpp, Heartbeats; the same rule on CAN):
// once tripped, the device drives nothing until the host has sent enable off and then enable on. The
// trip belongs to the device, so a host program that ends and a new one that starts find it still
// tripped: a new host that sends enable on from its first command gets no force.
void check_keeps_its_trip_across_a_host_restart(Rig& rig) {
  run_together(rig, 1, 5, push(1.0));
  CHECK_TRUE(rig.device().output().force_applied);
  for (int ms = 6; ms <= 40; ++ms) rig.device().step(ms * kMs);  // the first host program died at 5 ms
  CHECK_TRUE(rig.device().output().watchdog_tripped);

  // The new host asks for force from its first command; it reads the samples the device writes.
  rig.restart_host();
  int tripped_samples = 0;
  for (int ms = 41; ms <= 60; ++ms) {
    run_together(rig, ms, ms, push(1.0));
    hal::HapticSample sample{};
    if (rig.host().read_sample(ms * kMs, sample).status != ReadStatus::Fresh) continue;
    tripped_samples += (sample.status_bits & hal::haptic_status::kHostWatchdogTripped) != 0U ? 1 : 0;
  }
  sim::DeviceOutput output = rig.device().output();
  CHECK_TRUE(output.watchdog_tripped);
  CHECK_FALSE(output.force_applied);
  DOUBLES_EQUAL(0.0, output.force_n[2], 0.0);
  CHECK_EQUAL(1U, output.watchdog_trips);
  CHECK_TRUE(tripped_samples >= 10);  // shown to the new host (CAN may drop a backlog at its first read)

  run_together(rig, 61, 61, push(0.0, false));
  CHECK_FALSE(rig.device().output().watchdog_tripped);
  CHECK_FALSE(rig.device().output().force_applied);
  run_together(rig, 62, 62, push(1.0));
  output = rig.device().output();
  CHECK_TRUE(output.force_applied);
  DOUBLES_EQUAL(1.0, output.force_n[2], 1e-9);
}

}  // namespace

TEST_GROUP(SimulatedHapticDevice) {};

TEST(SimulatedHapticDevice, KeepsItsTrippedWatchdogAcrossAHostRestartOnThePioWindow) {
  PioRig rig;
  check_keeps_its_trip_across_a_host_restart(rig);
}

TEST(SimulatedHapticDevice, KeepsItsTrippedWatchdogAcrossAHostRestartOnCan) {
  CanRig rig;
  check_keeps_its_trip_across_a_host_restart(rig);
}

TEST(SimulatedHapticDevice, ZeroesForceWhenTheHostHeartbeatFreezesOnThePioWindow) {
  PioRig rig;
  check_zeroes_force_when_the_host_freezes(rig);
}

TEST(SimulatedHapticDevice, ZeroesForceWhenTheHostHeartbeatFreezesOnCan) {
  CanRig rig;
  check_zeroes_force_when_the_host_freezes(rig);
}

TEST(SimulatedHapticDevice, StaysOffAfterATripUntilTheHostReArmsOnThePioWindow) {
  PioRig rig;
  check_stays_off_after_a_trip_until_re_armed(rig);
}

TEST(SimulatedHapticDevice, StaysOffAfterATripUntilTheHostReArmsOnCan) {
  CanRig rig;
  check_stays_off_after_a_trip_until_re_armed(rig);
}

TEST(SimulatedHapticDevice, DrivesNoForceBeforeTheFirstCommandNorWhileDisabled) {
  PioRig rig;
  rig.device().step(1 * kMs);
  CHECK_FALSE(rig.device().output().force_applied);
  CHECK_FALSE(rig.device().output().watchdog_tripped);
  rig.device().step(100 * kMs);  // no host at all yet: nothing to trip
  CHECK_FALSE(rig.device().output().watchdog_tripped);
  run_together(rig, 101, 101, push(3.0, false));
  CHECK_FALSE(rig.device().output().force_applied);
  DOUBLES_EQUAL(0.0, rig.device().output().force_n[2], 0.0);
}

TEST(SimulatedHapticDevice, AFrozenDeviceWritesNothingAndReadsNothing) {
  PioRig rig;
  run_together(rig, 1, 3, push(1.0));
  CHECK_EQUAL(3U, rig.device().output().samples_written);
  rig.device().set_frozen(true);
  run_together(rig, 4, 10, push(2.0));
  const sim::DeviceOutput output = rig.device().output();
  CHECK_EQUAL(3U, output.samples_written);
  DOUBLES_EQUAL(1.0, output.force_n[2], 1e-9);  // a hung controller holds whatever it had
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, rig.host().read_sample(10 * kMs, sample).status);
  CHECK_EQUAL(3U, sample.sample_counter);
  CHECK_EQUAL(ReadStatus::Stale, rig.host().read_sample(11 * kMs, sample).status);
}

TEST(SimulatedHapticDevice, ReportsItsOwnFaultInTheStatusBitsAndDrivesNoForce) {
  PioRig rig;
  rig.device().set_device_fault(true);
  run_together(rig, 1, 2, push(1.0));
  CHECK_FALSE(rig.device().output().force_applied);
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, rig.host().read_sample(2 * kMs, sample).status);
  CHECK_TRUE((sample.status_bits & hal::haptic_status::kDeviceFault) != 0U);
}

TEST(SimulatedHapticDevice, OnItsOwnThreadZeroesForceSoonAfterTheHostStops) {
  PioRig rig;
  sim::SimulatedDeviceThread device_thread(rig.device());
  // Beat until the device has taken a command and drives it (bounded: a loaded machine is slow, not stuck).
  const hal::MonotonicNs give_up = hal::posix_clock::monotonic_now_ns() + 2'000 * kMs;
  hal::MonotonicNs last_write_ns = 0;
  while (!rig.device().output().force_applied && hal::posix_clock::monotonic_now_ns() < give_up) {
    last_write_ns = hal::posix_clock::monotonic_now_ns();  // the device cannot see this beat any earlier
    rig.send_plainly(push(2.0));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  CHECK_TRUE(rig.device().output().force_applied);

  // The host goes silent. The trip comes after the watchdog time, never before; generous bound on how late.
  while (rig.device().output().force_applied && hal::posix_clock::monotonic_now_ns() < last_write_ns + 2'000 * kMs) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const hal::MonotonicNs zeroed_after_ns = hal::posix_clock::monotonic_now_ns() - last_write_ns;
  device_thread.stop();
  CHECK_FALSE(rig.device().output().force_applied);
  CHECK_TRUE(rig.device().output().watchdog_tripped);
  CHECK_TRUE(zeroed_after_ns > sim::kDefaultHostWatchdogNs);
  std::printf("\n  simulated device on its thread: force zeroed %.1f ms after the host's last beat (watchdog %.0f ms)\n",
              static_cast<double>(zeroed_after_ns) * 1e-6, static_cast<double>(sim::kDefaultHostWatchdogNs) * 1e-6);
  // It ran: it took a command and later tripped, so at least two cycles (on a starved host, as under
  // ASan beside other tests, it may get few more than that in the watchdog's 20 ms).
  CHECK_TRUE(device_thread.cycles() >= 2);
}

TEST(SimulatedHapticDevice, AScriptedTrajectoryMovesLinearlyThroughItsWaypointsThenHolds) {
  const sim::SimulatedPose waypoints[] = {{{0.0, 0.0, 0.0}, {0.0, 0.0}},
                                          {{10.0, -20.0, 4.0}, {0.5, -0.5}},
                                          {{10.0, 0.0, 4.0}, {0.0, 0.0}}};
  const sim::PoseSource source = sim::scripted_trajectory(waypoints, 3, 100 * kMs, 10 * kMs);
  DOUBLES_EQUAL(0.0, source(1, 50 * kMs).position_mm[0], 0.0);  // before the start: the first waypoint
  const sim::SimulatedPose quarter = source(2, 102'500'000);
  DOUBLES_EQUAL(2.5, quarter.position_mm[0], 1e-9);
  DOUBLES_EQUAL(-5.0, quarter.position_mm[1], 1e-9);
  DOUBLES_EQUAL(0.125, quarter.angles_rad[0], 1e-9);
  const sim::SimulatedPose second_leg = source(3, 115 * kMs);
  DOUBLES_EQUAL(10.0, second_leg.position_mm[0], 1e-9);
  DOUBLES_EQUAL(-10.0, second_leg.position_mm[1], 1e-9);
  DOUBLES_EQUAL(-0.25, second_leg.angles_rad[1], 1e-9);
  DOUBLES_EQUAL(0.0, source(4, 1'000 * kMs).position_mm[1], 0.0);  // after the end: the last, held
}

TEST(SimulatedHapticDevice, WritesTheScriptedPoseTheHostThenReads) {
  const sim::SimulatedPose waypoints[] = {{{0.0, 0.0, 0.0}, {0.0, 0.0}}, {{100.0, 0.0, 0.0}, {0.0, 0.0}}};
  PioRig rig;
  sim::SimulatedHapticDevice scripted(rig.link, sim::scripted_trajectory(waypoints, 2, 0, 1'000 * kMs));
  scripted.step(250 * kMs);
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, rig.host().read_sample(250 * kMs, sample).status);
  DOUBLES_EQUAL(25.0, sample.position_mm[0], 1e-9);
}
