// The PIO shared memory backend's own behaviour, beyond the HapticDevice contract that
// tests/hal/haptic_device_tests.cpp runs on every backend (fresh, stale, lost, range,
// clamping, torn samples): a writer stuck mid-write, the device's own limits, the host heartbeat
// carried across a host restart, arming the device's host watchdog (a restarted host, a trip during
// the run), seqlock reads racing a real writer thread, and the time of one cycle.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/pio_shared_memory/pio_device_side.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/seqlock.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "sim/haptic_device/simulated_device_thread.hpp"
#include "sim/haptic_device/simulated_haptic_device.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"
#include "tests/sim/haptic_device/counter_pose.hpp"
#include "tests/support/haptic_test_values.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using test::consistent_with_counter;
using test::counter_pose;
using hal::ReadStatus;
using hal::WriteStatus;
using test::command_of;
using test::marker_sample;
namespace pio = hal::pio_shared_memory;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

}  // namespace

TEST_GROUP(PioHapticDevice) {
  test::WindowPair windows;
  std::unique_ptr<sim::PioDeviceLink> device_link;
  std::unique_ptr<sim::SimulatedHapticDevice> device;
  std::unique_ptr<pio::PioHapticDevice> host;

  void setup() override {
    windows = test::make_device_window();
    device_link = std::make_unique<sim::PioDeviceLink>(windows.device->window());
    device = std::make_unique<sim::SimulatedHapticDevice>(*device_link, counter_pose);
    test::open_host_window(windows);
    host = std::make_unique<pio::PioHapticDevice>(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange);
  }

  // One millisecond as the rig runs it: the device's cycle, then the host's (read, then write).
  hal::WriteResult cycle(int ms, const hal::HapticCommand& command) {
    device->step(ms * kMs);
    hal::HapticSample sample{};
    static_cast<void>(host->read_sample(ms * kMs, sample));
    return host->write_command(command);
  }

  // Cycles first_ms..last_ms with enable off: long enough for the host to arm the device (four).
  void arm_the_device(int first_ms, int last_ms) {
    for (int ms = first_ms; ms <= last_ms; ++ms) {
      CHECK_EQUAL(WriteStatus::Written, cycle(ms, command_of(0.0, 0.0, 0.0, false)).status);
    }
  }

  // A new host program on the same window, as a restarted stencil-rig maps the card again.
  void restart_the_host() {
    host.reset();
    test::open_host_window(windows);
    CHECK_TRUE(windows.host != nullptr);
    host = std::make_unique<pio::PioHapticDevice>(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange);
  }
};

// The contract's torn sample, carried on: a writer that never finishes also stops its heartbeat.
TEST(PioHapticDevice, AWriterStuckMidWriteIsBusyThenLostPastTheWatchdogTime) {
  device->step(1 * kMs);
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(1 * kMs, sample).status);

  // The device starts a write (odd sequence), changes half the fields and never finishes.
  pio::PoseBlock& pose = windows.device->window().pose;
  std::atomic_ref<std::uint32_t>(pose.sequence).fetch_add(1);
  pose.sample_counter = 99;
  pose.position_um[0] = 1;

  hal::HapticSample after = marker_sample();
  const hal::ReadResult busy = host->read_sample(2 * kMs, after);
  CHECK_EQUAL(ReadStatus::Rejected, busy.status);
  CHECK_EQUAL(HapticFault::SampleBusy, busy.reason);
  CHECK_EQUAL(0xDEADU, after.sample_counter);  // nothing of the half-written block reached the caller
  CHECK_EQUAL(1U, host->counters().busy_reads);
  CHECK_EQUAL(static_cast<std::uint64_t>(pio::kSeqlockAttempts), host->counters().torn_read_retries);
  CHECK_EQUAL(HapticFault::None, host->latched_fault());

  // Still stuck past the watchdog time: a disconnect, not a busy read forever.
  const hal::ReadResult lost = host->read_sample(1 * kMs + pio::kDefaultDeviceWatchdogNs + 1, after);
  CHECK_EQUAL(ReadStatus::Fault, lost.status);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, lost.reason);
  CHECK_EQUAL(0xDEADU, after.sample_counter);

  // The device recovers: its next write completes the block and the host takes it whole.
  device->step(60 * kMs);
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(60 * kMs, after).status);
  CHECK_EQUAL(2U, after.sample_counter);
  CHECK_TRUE(consistent_with_counter(after));
}

TEST(PioHapticDevice, TheDeviceRefusesACommandBeyondItsOwnLimits) {
  // A host that skipped its clamp: 5.001 N written straight into the block.
  pio::CommandWords words{};
  words.force_mn[2] = 5001;
  words.flags = pio::kCommandEnableBit;
  words.host_heartbeat = 1;
  pio::seqlock_write(windows.host->window().command, words);
  device->step(1 * kMs);
  sim::DeviceOutput output = device->output();
  CHECK_FALSE(output.force_applied);
  CHECK_TRUE(output.last_command_refused);
  DOUBLES_EQUAL(0.0, output.force_n[2], 0.0);
  CHECK_EQUAL(1U, device_link->counters().commands_out_of_range);

  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(1 * kMs, sample).status);
  CHECK_TRUE((sample.status_bits & hal::haptic_status::kCommandRejected) != 0U);

  // Unknown flag bits are refused too.
  words.force_mn[2] = 100;
  words.flags = 0x10U | pio::kCommandEnableBit;
  words.host_heartbeat = 2;
  pio::seqlock_write(windows.host->window().command, words);
  device->step(2 * kMs);
  CHECK_EQUAL(2U, device_link->counters().commands_out_of_range);
  CHECK_FALSE(device->output().force_applied);

  // A proper command from the host, once it has armed the device, is driven.
  arm_the_device(3, 7);
  CHECK_EQUAL(WriteStatus::Written, host->write_command(command_of(0.0, 0.0, 2.5)).status);
  device->step(8 * kMs);
  output = device->output();
  CHECK_TRUE(output.force_applied);
  DOUBLES_EQUAL(2.5, output.force_n[2], 1e-9);
}

// The window outlives the host program: a new one continues the heartbeat it finds there, so the
// device never sees it stand still (or go back) across a restart.
TEST(PioHapticDevice, ARestartedHostContinuesTheHostHeartbeatItFindsInTheWindow) {
  for (int write = 1; write <= 3; ++write) {
    CHECK_EQUAL(WriteStatus::Written, host->write_command(command_of(0.0, 0.0, 0.0, false)).status);
  }
  CHECK_EQUAL(3U, windows.device->window().command.host_heartbeat);
  pio::PioHapticDevice restarted(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange);
  CHECK_EQUAL(WriteStatus::Written, restarted.write_command(command_of(0.0, 0.0, 0.0, false)).status);
  CHECK_EQUAL(4U, windows.device->window().command.host_heartbeat);
}

// Issue 18 item 5: a host that starts while the device's host watchdog is still tripped from an
// earlier run (the previous stencil-rig died or was killed) must re-arm it with enable off before
// its enable on can drive anything; a host that sends enable on from its first cycle gets no force
// on any run after the first.
TEST(PioHapticDevice, ARestartedHostGetsForceThroughOnceItHasReArmedTheTrippedDevice) {
  // The first run pushes 2 N; then its program dies and the device trips 20 ms later.
  for (int ms = 1; ms <= 10; ++ms) CHECK_TRUE(cycle(ms, command_of(0.0, 0.0, 2.0)).status != WriteStatus::Fault);
  CHECK_TRUE(device->output().force_applied);
  for (int ms = 11; ms <= 40; ++ms) device->step(ms * kMs);
  CHECK_TRUE(device->output().watchdog_tripped);

  // The next run asks for force from its first cycle, as the controller does.
  restart_the_host();
  int first_force_ms = 0;
  bool saw_the_tripped_bit = false;
  for (int ms = 41; ms <= 200 && first_force_ms == 0; ++ms) {
    device->step(ms * kMs);
    if (device->output().force_applied) first_force_ms = ms;
    hal::HapticSample sample{};
    const hal::ReadResult read = host->read_sample(ms * kMs, sample);
    CHECK_EQUAL(ReadStatus::Fresh, read.status);  // the earlier run's trip is shown, not this run's fault
    saw_the_tripped_bit = saw_the_tripped_bit || (sample.status_bits & hal::haptic_status::kHostWatchdogTripped) != 0U;
    CHECK_TRUE(host->write_command(command_of(0.0, 0.0, 2.0)).status != WriteStatus::Fault);
  }
  CHECK_TRUE(saw_the_tripped_bit);
  CHECK_TEXT(first_force_ms != 0, "the device drove no force in the 160 ms after the host restarted");
  CHECK_TEXT(first_force_ms <= 41 + 4, "force came later than four device cycles after the restart");
  const sim::DeviceOutput output = device->output();
  DOUBLES_EQUAL(2.0, output.force_n[2], 1e-9);
  CHECK_FALSE(output.watchdog_tripped);
  CHECK_EQUAL(1U, output.watchdog_trips);
  CHECK_EQUAL(HapticFault::None, host->latched_fault());
}

TEST(PioHapticDevice, AHostStartingAgainstAnUntrippedDeviceDrivesForceWithinAFewCycles) {
  int first_force_ms = 0;
  for (int ms = 1; ms <= 20; ++ms) {
    device->step(ms * kMs);
    if (first_force_ms == 0 && device->output().force_applied) first_force_ms = ms;
    hal::HapticSample sample{};
    const hal::ReadResult read = host->read_sample(ms * kMs, sample);
    CHECK_TRUE(read.status == ReadStatus::Fresh);
    CHECK_EQUAL(0U, sample.status_bits & hal::haptic_status::kHostWatchdogTripped);
    CHECK_TRUE(host->write_command(command_of(0.0, 0.0, 2.0)).status != WriteStatus::Fault);
  }
  CHECK_TEXT(first_force_ms != 0 && first_force_ms <= 5, "force did not come within five device cycles");
  const sim::DeviceOutput output = device->output();
  CHECK_TRUE(output.force_applied);
  DOUBLES_EQUAL(2.0, output.force_n[2], 1e-9);
  CHECK_EQUAL(0U, output.watchdog_trips);
  CHECK_EQUAL(HapticFault::None, host->latched_fault());
}

TEST(PioHapticDevice, HoldsEnableOffUntilTheDeviceConfirmsItIsArmedWhateverTheCallerAsks) {
  const pio::CommandBlock& block = windows.device->window().command;
  // Before the device has written anything: enable on is held, and nothing of the force goes out.
  const hal::WriteResult first = host->write_command(command_of(0.0, 0.0, 2.0));
  CHECK_EQUAL(WriteStatus::Held, first.status);
  CHECK_EQUAL(HapticFault::None, first.reason);
  CHECK_EQUAL(0U, block.flags);
  CHECK_EQUAL(0, block.force_mn[2]);
  CHECK_EQUAL(1U, block.host_heartbeat);  // it still beats
  // Enable off is sent as given.
  CHECK_EQUAL(WriteStatus::Written, host->write_command(command_of(0.0, 0.0, 0.0, false)).status);

  // The device's samples say its watchdog is clear; the host trusts only one the device wrote after
  // it read the enable off (two samples on from the first pose read after it), then lets enable on through.
  int held = 0;
  for (int ms = 1; ms <= 10; ++ms) {
    const hal::WriteResult result = cycle(ms, command_of(0.0, 0.0, 2.0));
    if (result.status == WriteStatus::Held) {
      ++held;
      CHECK_EQUAL(0U, block.flags);
      CHECK_EQUAL(0, block.force_mn[2]);
    } else {
      CHECK_EQUAL(WriteStatus::Written, result.status);  // and never held again once armed
      CHECK_EQUAL(pio::kCommandEnableBit, block.flags);
      CHECK_EQUAL(2000, block.force_mn[2]);
    }
  }
  CHECK_EQUAL(2, held);  // ms 1 reads pose 1 (the first after the enable off), ms 3 reads pose 3: armed
  CHECK_TRUE(device->output().force_applied);
}

// A trip during the run means this host stalled past the device's 20 ms: the caller hears it once, as
// a fault with its own reason, and no force comes back until the caller has cleared it.
TEST(PioHapticDevice, ReportsATripDuringTheRunAsAFaultAndHoldsForceUntilTheCallerClearsIt) {
  for (int ms = 1; ms <= 10; ++ms) CHECK_TRUE(cycle(ms, command_of(0.0, 0.0, 2.0)).status != WriteStatus::Fault);
  CHECK_TRUE(device->output().force_applied);

  // The host stalls for 25 ms: the device trips.
  for (int ms = 11; ms <= 35; ++ms) device->step(ms * kMs);
  CHECK_TRUE(device->output().watchdog_tripped);
  hal::HapticSample sample = marker_sample();
  const hal::ReadResult tripped = host->read_sample(35 * kMs, sample);
  CHECK_EQUAL(ReadStatus::Fault, tripped.status);
  CHECK_EQUAL(HapticFault::HostWatchdogTripped, tripped.reason);
  CHECK_EQUAL(0xDEADU, sample.sample_counter);  // untouched
  CHECK_EQUAL(HapticFault::HostWatchdogTripped, host->latched_fault());
  CHECK_EQUAL(hal::HapticLinkState::Connected, host->link_state());  // the device itself is fine

  // A caller that carries on asking for force gets none: enable off goes out (re-arming the device)
  // for as long as the trip is latched; the samples come as usual, the bit in them until re-armed.
  for (int ms = 36; ms <= 45; ++ms) {
    device->step(ms * kMs);
    CHECK_FALSE(device->output().force_applied);
    const hal::ReadResult read = host->read_sample(ms * kMs, sample);
    CHECK_EQUAL(ReadStatus::Fresh, read.status);
    CHECK_EQUAL(WriteStatus::Held, host->write_command(command_of(0.0, 0.0, 2.0)).status);
  }
  CHECK_FALSE(device->output().watchdog_tripped);
  CHECK_EQUAL(0U, sample.status_bits & hal::haptic_status::kHostWatchdogTripped);
  CHECK_EQUAL(HapticFault::HostWatchdogTripped, host->latched_fault());

  host->clear_fault();
  CHECK_EQUAL(WriteStatus::Written, cycle(46, command_of(0.0, 0.0, 2.0)).status);
  device->step(47 * kMs);
  CHECK_TRUE(device->output().force_applied);
  DOUBLES_EQUAL(2.0, device->output().force_n[2], 1e-9);
  CHECK_EQUAL(1U, device->output().watchdog_trips);
}

TEST(PioHapticDevice, AfterATripForceWaitsForClearFaultEvenWhenTheLatchHoldsAnEarlierFault) {
  for (int ms = 1; ms <= 10; ++ms) CHECK_TRUE(cycle(ms, command_of(0.0, 0.0, 2.0)).status != WriteStatus::Fault);
  CHECK_TRUE(device->output().force_applied);
  // The whole box stalls: the device's controller and the host. The host, first back, finds the
  // device heartbeat frozen; then the device comes back and trips on the host's frozen heartbeat.
  device->step(11 * kMs);  // it took the host's last command
  hal::HapticSample sample{};
  CHECK_EQUAL(ReadStatus::Fresh, host->read_sample(11 * kMs, sample).status);
  device->set_frozen(true);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, host->read_sample(70 * kMs, sample).reason);
  device->set_frozen(false);
  device->step(71 * kMs);
  const hal::ReadResult tripped = host->read_sample(71 * kMs, sample);
  CHECK_EQUAL(ReadStatus::Fault, tripped.status);
  CHECK_EQUAL(HapticFault::HostWatchdogTripped, tripped.reason);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, host->latched_fault());  // the first reason stays

  for (int ms = 72; ms <= 80; ++ms) CHECK_EQUAL(WriteStatus::Held, cycle(ms, command_of(0.0, 0.0, 2.0)).status);
  CHECK_FALSE(device->output().watchdog_tripped);
  host->clear_fault();
  CHECK_EQUAL(WriteStatus::Written, cycle(81, command_of(0.0, 0.0, 2.0)).status);
  device->step(82 * kMs);
  CHECK_TRUE(device->output().force_applied);
}

TEST(PioHapticDevice, ABackendWithoutAWindowReportsNotOpenAndLatchesIt) {
  pio::PioHapticDevice closed(nullptr, stencil::board::sherline_suzuki::kCentredDeviceRange);
  CHECK_EQUAL(hal::HapticLinkState::Closed, closed.link_state());
  hal::HapticSample sample{};
  const hal::ReadResult read = closed.read_sample(0, sample);
  CHECK_EQUAL(ReadStatus::Fault, read.status);
  CHECK_EQUAL(HapticFault::NotOpen, read.reason);
  CHECK_EQUAL(WriteStatus::Fault, closed.write_command(command_of(1.0, 0.0, 0.0)).status);
  CHECK_EQUAL(HapticFault::NotOpen, closed.latched_fault());
}

TEST(PioHapticDevice, NeverAcceptsATornSampleWhileTheSimulatedDeviceWritesAt1kHz) {
  // A watchdog far beyond any scheduling hiccup: this test is about consistency, not timing.
  pio::PioHapticDevice reader(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange, 10'000'000'000);
  sim::SimulatedDeviceThread device_thread(*device);
  const hal::MonotonicNs end = hal::posix_clock::monotonic_now_ns() + 300 * kMs;
  int reads = 0;
  int fresh = 0;
  int inconsistent = 0;
  std::uint32_t previous_counter = 0;
  int went_backwards = 0;
  while (hal::posix_clock::monotonic_now_ns() < end) {
    hal::HapticSample sample{};
    const hal::ReadResult result = reader.read_sample(hal::posix_clock::monotonic_now_ns(), sample);
    ++reads;
    if (result.status != ReadStatus::Fresh) continue;
    ++fresh;
    if (!consistent_with_counter(sample)) ++inconsistent;
    if (sample.sample_counter <= previous_counter) ++went_backwards;
    previous_counter = sample.sample_counter;
  }
  device_thread.stop();
  CHECK_EQUAL(0, inconsistent);
  CHECK_EQUAL(0, went_backwards);
  CHECK_TRUE(reads > 1000);
  CHECK_TRUE(fresh >= 30);  // 300 nominal; a loaded machine may run the device late, never not at all
  CHECK_EQUAL(HapticFault::None, reader.latched_fault());
}

TEST(PioHapticDevice, NeverAcceptsATornSampleFromAWriterHammeringTheWindow) {
  pio::PioDeviceSide writer_side(windows.device->window());
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (std::uint32_t k = 1; !stop.load(std::memory_order_relaxed); ++k) {
      const std::int32_t value = static_cast<std::int32_t>(k % 100000U);
      writer_side.publish_pose(pio::PoseWords{k, {value, -value, value / 2}, {value, -value}, k, k});
    }
  });
  pio::PioHapticDevice reader(&windows.host->window(), stencil::board::sherline_suzuki::kCentredDeviceRange, 10'000'000'000);
  int fresh = 0;
  int inconsistent = 0;
  const hal::MonotonicNs end = hal::posix_clock::monotonic_now_ns() + 5'000 * kMs;
  while (fresh < 50000 && hal::posix_clock::monotonic_now_ns() < end) {
    hal::HapticSample sample{};
    if (reader.read_sample(0, sample).status != ReadStatus::Fresh) continue;
    ++fresh;
    // Back to the integers the writer wrote: every field must come from the same k.
    const long value = static_cast<long>(sample.sample_counter % 100000U);
    if (std::lround(sample.position_mm[0] * 1e3) != value || std::lround(sample.position_mm[1] * 1e3) != -value ||
        std::lround(sample.position_mm[2] * 1e3) != value / 2 || std::lround(sample.angles_rad[0] * 1e6) != value ||
        std::lround(sample.angles_rad[1] * 1e6) != -value || sample.device_heartbeat != sample.sample_counter ||
        sample.status_bits != sample.sample_counter) {
      ++inconsistent;
    }
  }
  stop = true;
  writer.join();
  std::printf("\n  pio_shared_memory: %d fresh samples from a hammering writer, %llu retries after a torn read, "
              "%llu busy reads\n",
              fresh, static_cast<unsigned long long>(reader.counters().torn_read_retries),
              static_cast<unsigned long long>(reader.counters().busy_reads));
  CHECK_EQUAL(0, inconsistent);
  // Enough whole samples to have checked (tens of thousands on a quiet machine; a loaded one that
  // shares a core between the writer and the reader was seen to give 252 in the 5 s).
  CHECK_TRUE(fresh >= 100);
}

TEST(PioHapticDevice, MeasuresTheReadAndWriteOfOneCycle) {
  constexpr int kCycles = 20000;
  std::vector<long long> durations_ns;
  durations_ns.reserve(kCycles);
  hal::HapticSample sample{};
  int fresh = 0;
  int written = 0;
  for (int cycle = 1; cycle <= kCycles; ++cycle) {
    device->step(cycle * kMs);  // the device's write, not timed
    const auto start = std::chrono::steady_clock::now();
    const hal::ReadResult read = host->read_sample(cycle * kMs, sample);
    const hal::WriteResult write = host->write_command(command_of(0.001 * cycle, 0.0, 1.0));
    const auto stop = std::chrono::steady_clock::now();
    durations_ns.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
    fresh += read.status == ReadStatus::Fresh ? 1 : 0;
    written += write.status != WriteStatus::Fault ? 1 : 0;
  }
  std::nth_element(durations_ns.begin(), durations_ns.begin() + kCycles / 2, durations_ns.end());
  std::printf("\n  pio_shared_memory: read+write of one cycle: median %lld ns over %d cycles\n",
              durations_ns[kCycles / 2], kCycles);
  CHECK_EQUAL(kCycles, fresh);
  CHECK_EQUAL(kCycles, written);
}
