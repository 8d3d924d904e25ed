// The hal::HapticDevice contract (hal/haptic_device.hpp), written once and run against every backend:
// the in-process direct device (sim/haptic_device/direct_haptic_device.hpp), the PIO window over a
// memfd (hal/pio_shared_memory) and CAN over a socket pair (hal/socketcan), each with the device's
// side played by the test through the same link the simulated device uses. Fresh, stale, rejected and
// fault reads, the fault latch, the range checks, force clamping, both heartbeats and torn samples.
// Where a backend cannot show a case by its nature (the direct device has no wire to tear and no
// heartbeat to lose) the case says so and checks what that backend does instead.
// Backend-specific behaviour (PIO arming, CAN error frames and backlogs, timing) stays in the
// backends' own suites.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/haptic_device.hpp"
#include "hal/pio_shared_memory/pio_haptic_device.hpp"
#include "hal/pio_shared_memory/seqlock.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "hal/socketcan/socketcan_haptic_device.hpp"
#include "sim/haptic_device/can_device_link.hpp"
#include "sim/haptic_device/direct_haptic_device.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "tests/fakes/fake_clock.hpp"
#include "tests/hal/pio_shared_memory/haptic_result_strings.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"
#include "tests/support/can_socket_pair.hpp"
#include "tests/support/haptic_test_values.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using hal::HapticFault;
using hal::ReadStatus;
using hal::WriteStatus;
using test::marker_sample;
namespace pio = hal::pio_shared_memory;
namespace can = hal::socketcan;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;
constexpr hal::HapticRange kRange = board::sherline_suzuki::kCentredDeviceRange;

// ---- What the contract needs of a backend ----------------------------------------------------------

// A backend under test and the device's side of it, behind one interface so each case is written once.
class BackendUnderTest {
 public:
  BackendUnderTest() = default;
  BackendUnderTest(const BackendUnderTest&) = delete;
  BackendUnderTest& operator=(const BackendUnderTest&) = delete;
  virtual ~BackendUnderTest() = default;

  virtual hal::HapticDevice& host() = 0;
  // The device side writes one whole sample, every field as given.
  virtual void publish(const hal::HapticSample& sample) = 0;
  // The device side starts writing `sample` and leaves it torn (what a transport can show: a write
  // caught half-way, the halves of two poses paired). Returns the reason the backend must refuse it
  // with, or nothing where the transport cannot tear.
  virtual std::optional<HapticFault> tear(const hal::HapticSample& sample) = 0;
  // The command the device side drives now: the newest one that reached it (zero, enable off, before any).
  virtual sim::DeviceCommand device_command() = 0;
  // The backend's device-heartbeat watchdog time; nothing when it has no device heartbeat to watch.
  [[nodiscard]] virtual std::optional<hal::MonotonicNs> device_watchdog_ns() const = 0;
  // Whether the device side sees a host heartbeat (sim::DeviceCommand::host_heartbeat).
  [[nodiscard]] virtual bool carries_host_heartbeat() const = 0;
  // The host program starts again on the same device side with another board's range (the device
  // side, and what it last received, stay).
  virtual void restart_host(const hal::HapticRange& range) = 0;
  // Whether a NaN or infinity the device side gives reaches the backend as one (no wire carries one:
  // the device's link saturates it, so a wire backend sees a number, perhaps out of range).
  [[nodiscard]] virtual bool carries_non_finite() const = 0;
};

// In process: the device side publishes into the backend itself, the command is read back from it.
class DirectBackend final : public BackendUnderTest {
 public:
  hal::HapticDevice& host() override { return *device_; }
  void publish(const hal::HapticSample& sample) override { device_->publish(sample); }
  // A publish is one call on the cycle's own thread: there is nothing half-written to read.
  std::optional<HapticFault> tear(const hal::HapticSample&) override { return std::nullopt; }
  sim::DeviceCommand device_command() override {
    const hal::HapticCommand& rendered = device_->rendered();
    return {{rendered.force_n[0], rendered.force_n[1], rendered.force_n[2]},
            {rendered.torque_nmm[0], rendered.torque_nmm[1]},
            rendered.cycle_counter,
            0,
            rendered.enable};
  }
  [[nodiscard]] std::optional<hal::MonotonicNs> device_watchdog_ns() const override { return std::nullopt; }
  [[nodiscard]] bool carries_host_heartbeat() const override { return false; }
  [[nodiscard]] bool carries_non_finite() const override { return true; }
  // In process the device is the backend: a new one, rendering nothing until written.
  void restart_host(const hal::HapticRange& range) override { device_ = std::make_unique<sim::DirectHapticDevice>(range); }

 private:
  std::unique_ptr<sim::DirectHapticDevice> device_ = std::make_unique<sim::DirectHapticDevice>(kRange);
};

// The PIO window: a memfd mapped twice, the device's side through sim::PioDeviceLink.
class PioBackend final : public BackendUnderTest {
 public:
  PioBackend() {
    test::open_host_window(windows_);
    CHECK_TRUE(windows_.host != nullptr);
    backend_ = std::make_unique<pio::PioHapticDevice>(&windows_.host->window(), kRange);
  }
  hal::HapticDevice& host() override { return *backend_; }
  void publish(const hal::HapticSample& sample) override { link_.publish(sample); }
  // The device begins a write (odd sequence), changes part of the block and stops there.
  std::optional<HapticFault> tear(const hal::HapticSample& sample) override {
    pio::PoseBlock& pose = windows_.device->window().pose;
    std::atomic_ref<std::uint32_t>(pose.sequence).fetch_add(1U);
    pio::store_word(pose.sample_counter, sample.sample_counter);
    pio::store_word(pose.position_um[0], static_cast<std::int32_t>(std::lround(sample.position_mm[0] * 1e3)));
    return HapticFault::SampleBusy;
  }
  sim::DeviceCommand device_command() override {
    sim::DeviceCommand received{};
    if (link_.poll(received) == sim::CommandPoll::New) command_ = received;
    return command_;
  }
  [[nodiscard]] std::optional<hal::MonotonicNs> device_watchdog_ns() const override {
    return pio::kDefaultDeviceWatchdogNs;
  }
  [[nodiscard]] bool carries_host_heartbeat() const override { return true; }
  [[nodiscard]] bool carries_non_finite() const override { return false; }
  void restart_host(const hal::HapticRange& range) override {
    backend_ = std::make_unique<pio::PioHapticDevice>(&windows_.host->window(), range);
  }

 private:
  test::WindowPair windows_ = test::make_device_window();
  sim::PioDeviceLink link_{windows_.device->window()};  // initialises the header the host checks
  std::unique_ptr<pio::PioHapticDevice> backend_;
  sim::DeviceCommand command_{};
};

// CAN over a socket pair, the device's side through sim::CanDeviceLink.
class CanBackend final : public BackendUnderTest {
 public:
  CanBackend() { CHECK_TRUE(sockets_.open()); }
  hal::HapticDevice& host() override { return *backend_; }
  void publish(const hal::HapticSample& sample) override { link_.publish(sample); }
  // A pose travels as two frames; a lost frame pairs the PoseA of one sample with the PoseB of another.
  std::optional<HapticFault> tear(const hal::HapticSample& sample) override {
    const auto counter = static_cast<std::uint8_t>(sample.sample_counter & 0xFFU);
    can_frame pose_a;
    can_frame pose_b;
    CHECK_TRUE(can::encode_pose(can::PoseWire{counter, {0, 0, 0}, {0, 0}}, pose_a, pose_b));
    can_frame next_a;
    can_frame next_b;
    CHECK_TRUE(can::encode_pose(can::PoseWire{static_cast<std::uint8_t>(counter + 1U), {1, 1, 1}, {0, 0}}, next_a, next_b));
    CHECK_TRUE(sockets_.device.send(pose_a) == can::TransferStatus::Done);
    CHECK_TRUE(sockets_.device.send(next_b) == can::TransferStatus::Done);
    return HapticFault::BadFrame;
  }
  sim::DeviceCommand device_command() override {
    sim::DeviceCommand received{};
    if (link_.poll(received) == sim::CommandPoll::New) command_ = received;
    return command_;
  }
  [[nodiscard]] std::optional<hal::MonotonicNs> device_watchdog_ns() const override {
    return can::kDefaultDeviceWatchdogNs;
  }
  [[nodiscard]] bool carries_host_heartbeat() const override { return true; }
  [[nodiscard]] bool carries_non_finite() const override { return false; }
  void restart_host(const hal::HapticRange& range) override {
    backend_ = std::make_unique<can::SocketCanHapticDevice>(&sockets_.host, range);
  }

 private:
  test::CanSocketPair sockets_;
  sim::CanDeviceLink link_{sockets_.device};
  std::unique_ptr<can::SocketCanHapticDevice> backend_ =
      std::make_unique<can::SocketCanHapticDevice>(&sockets_.host, kRange);
  sim::DeviceCommand command_{};
};

// ---- The contract, written once ---------------------------------------------------------------------

// One backend, the device side's counters, and the time, as each case drives them.
class Contract {
 public:
  explicit Contract(BackendUnderTest& backend) : backend_(backend) {}

  hal::HapticDevice& host() { return backend_.host(); }
  BackendUnderTest& backend() { return backend_; }
  test::FakeClock& clock() { return clock_; }

  // The device's next sample at this pose: counter and heartbeat one on (the heartbeat stays when
  // `beat` is false: a controller whose samples come but whose heartbeat froze).
  hal::HapticSample next_sample(double x, double y, double z, double angle0 = 0.0, double angle1 = 0.0, bool beat = true) {
    ++counter_;
    if (beat) ++heartbeat_;
    return hal::HapticSample{{x, y, z}, {angle0, angle1}, counter_, 0U, heartbeat_};
  }
  hal::HapticSample publish(double x, double y, double z, double angle0 = 0.0, double angle1 = 0.0) {
    const hal::HapticSample sample = next_sample(x, y, z, angle0, angle1);
    backend_.publish(sample);
    return sample;
  }
  hal::ReadResult read(hal::HapticSample& out) { return host().read_sample(clock_.now_ns(), out); }

  // What a cycle does before it asks for force: a few 1 ms cycles of sample, read, enable off. (The
  // PIO backend holds enable on until the device has confirmed, in its samples, that it is armed.)
  void bring_up() {
    for (int cycle = 0; cycle < 5; ++cycle) {
      CHECK_TRUE(clock_.advance_ms(1));
      static_cast<void>(publish(0.0, 0.0, 0.0));
      hal::HapticSample sample{};
      CHECK_EQUAL(ReadStatus::Fresh, read(sample).status);
      CHECK_EQUAL(WriteStatus::Written, host().write_command(test::command_of(0.0, 0.0, 0.0, false)).status);
    }
  }

 private:
  BackendUnderTest& backend_;
  test::FakeClock clock_{0};
  std::uint32_t counter_ = 0;
  std::uint32_t heartbeat_ = 0;
};

void check_same_pose(const hal::HapticSample& expected, const hal::HapticSample& actual) {
  for (int axis = 0; axis < 3; ++axis) DOUBLES_EQUAL(expected.position_mm[axis], actual.position_mm[axis], 1e-9);
  for (int angle = 0; angle < 2; ++angle) DOUBLES_EQUAL(expected.angles_rad[angle], actual.angles_rad[angle], 1e-9);
}

void a_fresh_read_gives_the_new_sample_once(Contract& contract) {
  hal::HapticSample out = marker_sample();
  CHECK_EQUAL(ReadStatus::Stale, contract.read(out).status);  // nothing published yet
  CHECK_EQUAL(0xDEADU, out.sample_counter);

  // Values every wire carries exactly: whole micrometres, angles on 100 urad steps.
  hal::HapticSample published = contract.next_sample(12.345, -6.789, 100.0, 0.5, -0.25);
  published.status_bits = hal::haptic_status::kForceApplied | hal::haptic_status::kDeviceFault;
  contract.backend().publish(published);
  const hal::ReadResult fresh = contract.read(out);
  CHECK_EQUAL(ReadStatus::Fresh, fresh.status);
  CHECK_EQUAL(HapticFault::None, fresh.reason);
  check_same_pose(published, out);
  CHECK_EQUAL(published.sample_counter, out.sample_counter);
  CHECK_EQUAL(published.device_heartbeat, out.device_heartbeat);
  CHECK_EQUAL(published.status_bits, out.status_bits);  // as the device set them
  CHECK_EQUAL(hal::HapticLinkState::Connected, contract.host().link_state());

  // Nothing new since: Stale, and `out` is not touched.
  out = marker_sample();
  const hal::ReadResult again = contract.read(out);
  CHECK_EQUAL(ReadStatus::Stale, again.status);
  CHECK_EQUAL(HapticFault::None, again.reason);
  CHECK_EQUAL(0xDEADU, out.sample_counter);
  DOUBLES_EQUAL(12345.0, out.position_mm[0], 0.0);

  const hal::HapticCounters counters = contract.host().counters();
  CHECK_EQUAL(1U, counters.samples_accepted);
  CHECK_EQUAL(2U, counters.stale_reads);
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());
}

void a_read_gives_the_newest_of_several_samples(Contract& contract) {
  static_cast<void>(contract.publish(1.0, 0.0, 0.0));
  static_cast<void>(contract.publish(2.0, 0.0, 0.0));
  const hal::HapticSample newest = contract.publish(3.0, 0.0, 0.0);
  hal::HapticSample out{};
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  check_same_pose(newest, out);
  CHECK_EQUAL(newest.sample_counter, out.sample_counter);
  CHECK_EQUAL(ReadStatus::Stale, contract.read(out).status);
}

// A device that stops publishing reads Stale (not a fault) up to the watchdog time, then Fault /
// DeviceHeartbeatLost: a disconnect, not a hang.
void a_silent_device_reads_stale_then_lost_after_the_watchdog_time(Contract& contract) {
  hal::HapticSample out{};
  static_cast<void>(contract.publish(0.0, 0.0, 0.0));
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  const hal::MonotonicNs last_beat_ns = contract.clock().now_ns();
  const std::optional<hal::MonotonicNs> bound = contract.backend().device_watchdog_ns();
  const hal::MonotonicNs watched_ns = bound.value_or(10'000 * kMs);

  for (hal::MonotonicNs now = last_beat_ns + kMs; now <= last_beat_ns + watched_ns; now += kMs) {
    CHECK_TRUE(contract.clock().set_ns(now));
    out = marker_sample();
    const hal::ReadResult stale = contract.read(out);
    CHECK_EQUAL(ReadStatus::Stale, stale.status);
    CHECK_EQUAL(0xDEADU, out.sample_counter);
  }
  CHECK_EQUAL(hal::HapticLinkState::Connected, contract.host().link_state());

  CHECK_TRUE(contract.clock().set_ns(last_beat_ns + watched_ns + 1));
  const hal::ReadResult late = contract.read(out);
  if (!bound) {
    // The direct device lives in the simulation's own process: it has no heartbeat, and a
    // simulation that stops publishing is a still handle, never a lost one.
    CHECK_EQUAL(ReadStatus::Stale, late.status);
    CHECK_EQUAL(hal::HapticLinkState::Connected, contract.host().link_state());
    return;
  }
  CHECK_EQUAL(ReadStatus::Fault, late.status);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, late.reason);
  CHECK_EQUAL(0xDEADU, out.sample_counter);
  CHECK_EQUAL(hal::HapticLinkState::Disconnected, contract.host().link_state());
}

// The device heartbeat, not the sample counter, says whether the device's controller runs.
void samples_whose_heartbeat_froze_are_lost_after_the_watchdog_time(Contract& contract) {
  hal::HapticSample out{};
  contract.backend().publish(contract.next_sample(0.0, 0.0, 0.0));
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  const hal::MonotonicNs last_beat_ns = contract.clock().now_ns();
  const std::optional<hal::MonotonicNs> bound = contract.backend().device_watchdog_ns();
  const hal::MonotonicNs watched_ns = bound.value_or(100 * kMs);
  for (hal::MonotonicNs now = last_beat_ns + kMs; now <= last_beat_ns + watched_ns; now += kMs) {
    CHECK_TRUE(contract.clock().set_ns(now));
    contract.backend().publish(contract.next_sample(0.0, 0.0, 0.0, 0.0, 0.0, false));
    CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  }
  CHECK_TRUE(contract.clock().set_ns(last_beat_ns + watched_ns + 1));
  contract.backend().publish(contract.next_sample(0.0, 0.0, 0.0, 0.0, 0.0, false));
  const hal::ReadResult late = contract.read(out);
  if (!bound) {
    // In process there is no controller apart from the simulation to freeze: the heartbeat field is
    // carried, not watched.
    CHECK_EQUAL(ReadStatus::Fresh, late.status);
    return;
  }
  CHECK_EQUAL(ReadStatus::Fault, late.status);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, late.reason);
}

// The first fault is latched until clear_fault(), through a recovery and a later fault alike;
// refused input is counted, never latched.
void a_fault_is_latched_until_cleared_and_refused_input_is_not(Contract& contract) {
  hal::HapticSample out{};
  static_cast<void>(contract.publish(0.0, 0.0, 0.0));
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  static_cast<void>(contract.publish(400.0, 0.0, 0.0));  // beyond the reach
  CHECK_EQUAL(ReadStatus::Rejected, contract.read(out).status);
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());

  const std::optional<hal::MonotonicNs> bound = contract.backend().device_watchdog_ns();
  if (!bound) {
    // The direct device has no link that can fail: it never reports a fault, so its latch stays empty.
    CHECK_TRUE(contract.clock().advance_ms(10'000));
    CHECK_TRUE(contract.read(out).status != ReadStatus::Fault);
    contract.host().clear_fault();
    CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());
    return;
  }
  CHECK_TRUE(contract.clock().advance_ns(*bound + 1));
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, contract.read(out).reason);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, contract.host().latched_fault());

  // The device is back: fresh samples, connected, and the latch still holds for the cycle to see.
  CHECK_TRUE(contract.clock().advance_ms(1));
  const hal::HapticSample back = contract.publish(1.0, 2.0, 3.0);
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  check_same_pose(back, out);
  CHECK_EQUAL(hal::HapticLinkState::Connected, contract.host().link_state());
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, contract.host().latched_fault());

  contract.host().clear_fault();
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());
  // Lost again: the latch takes the new fault.
  CHECK_TRUE(contract.clock().advance_ns(*bound + 1));
  CHECK_EQUAL(ReadStatus::Fault, contract.read(out).status);
  CHECK_EQUAL(HapticFault::DeviceHeartbeatLost, contract.host().latched_fault());
}

void check_refused(Contract& contract, const hal::HapticSample& sample, HapticFault reason) {
  contract.backend().publish(sample);
  hal::HapticSample out = marker_sample();
  const hal::ReadResult refused = contract.read(out);
  CHECK_EQUAL(ReadStatus::Rejected, refused.status);
  CHECK_EQUAL(reason, refused.reason);
  CHECK_EQUAL(0xDEADU, out.sample_counter);
  CHECK_EQUAL(ReadStatus::Stale, contract.read(out).status);  // refused once, then nothing new
}

// The range of the board (kCentredDeviceRange: 250 x 125 x 125 mm half-reach plus 25 mm, angles
// 3.2 rad) is inclusive at its edges and refuses anything past them, on every backend.
void samples_are_accepted_up_to_the_range_and_refused_past_it(Contract& contract) {
  hal::HapticSample out{};
  const hal::HapticSample edge = contract.publish(275.0, -150.0, 150.0, 3.2, -3.2);
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  check_same_pose(edge, out);

  check_refused(contract, contract.next_sample(275.001, 0.0, 0.0), HapticFault::SampleOutOfRange);
  check_refused(contract, contract.next_sample(0.0, -150.001, 0.0), HapticFault::SampleOutOfRange);
  check_refused(contract, contract.next_sample(0.0, 0.0, 150.001), HapticFault::SampleOutOfRange);
  check_refused(contract, contract.next_sample(0.0, 0.0, 0.0, 3.3, 0.0), HapticFault::SampleOutOfRange);
  check_refused(contract, contract.next_sample(0.0, 0.0, 0.0, 0.0, -3.3), HapticFault::SampleOutOfRange);
  // Beyond what any wire carries (a wire's device saturates it; the direct device keeps it).
  check_refused(contract, contract.next_sample(-1e12, 0.0, 0.0), HapticFault::SampleOutOfRange);
  CHECK_EQUAL(6U, contract.host().counters().samples_out_of_range);
  CHECK_EQUAL(1U, contract.host().counters().samples_accepted);

  // A good sample after all that comes through as if nothing happened.
  const hal::HapticSample good = contract.publish(-10.0, 20.0, -30.0);
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  check_same_pose(good, out);
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());
}

void a_sample_that_is_not_finite_is_refused_naming_why(Contract& contract) {
  const double kInfinity = HUGE_VAL;
  if (!contract.backend().carries_non_finite()) {
    // No wire carries a NaN or an infinity: the device's link turns an infinity into the largest
    // value its field holds (refused as out of range, below) and a NaN into a number, so a wire
    // backend never meets SampleNotFinite.
    check_refused(contract, contract.next_sample(0.0, kInfinity, 0.0), HapticFault::SampleOutOfRange);
    check_refused(contract, contract.next_sample(0.0, 0.0, 0.0, -kInfinity, 0.0), HapticFault::SampleOutOfRange);
    return;
  }
  check_refused(contract, contract.next_sample(std::nan(""), 0.0, 0.0), HapticFault::SampleNotFinite);
  check_refused(contract, contract.next_sample(0.0, kInfinity, 0.0), HapticFault::SampleNotFinite);
  check_refused(contract, contract.next_sample(0.0, 0.0, 0.0, 0.0, std::nan("")), HapticFault::SampleNotFinite);
  CHECK_EQUAL(3U, contract.host().counters().samples_out_of_range);
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());
}

// A sample the device was still writing, or whose parts came from two samples, is never given.
void a_torn_sample_is_refused_and_the_next_whole_one_given(Contract& contract) {
  hal::HapticSample out{};
  static_cast<void>(contract.publish(1.0, 1.0, 1.0));
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);

  const std::optional<HapticFault> reason = contract.backend().tear(contract.next_sample(99.0, 99.0, 99.0));
  if (!reason) {
    // The direct device's sample moves by one call on the reading thread: it cannot be torn. Its
    // next sample is given whole, as below.
    const hal::HapticSample whole = contract.publish(2.0, 2.0, 2.0);
    CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
    check_same_pose(whole, out);
    return;
  }
  CHECK_TRUE(contract.clock().advance_ms(1));
  out = marker_sample();
  const hal::ReadResult torn = contract.read(out);
  CHECK_EQUAL(ReadStatus::Rejected, torn.status);
  CHECK_EQUAL(*reason, torn.reason);
  CHECK_EQUAL(0xDEADU, out.sample_counter);
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());

  CHECK_TRUE(contract.clock().advance_ms(1));
  const hal::HapticSample whole = contract.publish(-2.0, 3.0, -4.0, 0.1, -0.2);
  CHECK_EQUAL(ReadStatus::Fresh, contract.read(out).status);
  check_same_pose(whole, out);
  CHECK_EQUAL(whole.sample_counter, out.sample_counter);
}

void a_command_within_the_range_reaches_the_device_as_given(Contract& contract) {
  contract.bring_up();
  hal::HapticCommand command = test::command_of(1.5, -0.25, 2.0);
  command.torque_nmm[0] = 120.0;
  command.torque_nmm[1] = -40.0;
  const hal::WriteResult result = contract.host().write_command(command);
  CHECK_EQUAL(WriteStatus::Written, result.status);
  CHECK_EQUAL(HapticFault::None, result.reason);
  const sim::DeviceCommand driven = contract.backend().device_command();
  CHECK_TRUE(driven.enable);
  DOUBLES_EQUAL(1.5, driven.force_n[0], 1e-9);
  DOUBLES_EQUAL(-0.25, driven.force_n[1], 1e-9);
  DOUBLES_EQUAL(2.0, driven.force_n[2], 1e-9);
  DOUBLES_EQUAL(120.0, driven.torque_nmm[0], 1e-9);
  DOUBLES_EQUAL(-40.0, driven.torque_nmm[1], 1e-9);
  CHECK_EQUAL(7U, driven.cycle_counter);
  CHECK_EQUAL(0U, contract.host().counters().commands_clamped);

  // Enable off: the device drives nothing, whatever the numbers.
  CHECK_EQUAL(WriteStatus::Written, contract.host().write_command(test::command_of(1.0, 1.0, 1.0, false)).status);
  CHECK_FALSE(contract.backend().device_command().enable);
}

// Force and torque are scaled down in magnitude, direction kept, to the board's 5 N and 200 N.mm.
void force_and_torque_are_clamped_to_their_limits(Contract& contract) {
  contract.bring_up();
  hal::HapticCommand command = test::command_of(6.0, 8.0, 0.0);  // 10 N
  command.torque_nmm[0] = 300.0;
  command.torque_nmm[1] = -400.0;  // 500 N.mm
  const hal::WriteResult result = contract.host().write_command(command);
  CHECK_EQUAL(WriteStatus::Clamped, result.status);
  CHECK_EQUAL(HapticFault::None, result.reason);
  sim::DeviceCommand driven = contract.backend().device_command();
  CHECK_TRUE(driven.enable);
  DOUBLES_EQUAL(3.0, driven.force_n[0], 1e-3);  // the wires carry whole millinewtons
  DOUBLES_EQUAL(4.0, driven.force_n[1], 1e-3);
  DOUBLES_EQUAL(0.0, driven.force_n[2], 1e-3);
  DOUBLES_EQUAL(120.0, driven.torque_nmm[0], 0.011);  // and CAN 10 mN.mm steps
  DOUBLES_EQUAL(-160.0, driven.torque_nmm[1], 0.011);

  // A diagonal far past the limit: what reaches the device is at most 5 N, never a rounding more.
  CHECK_EQUAL(WriteStatus::Clamped, contract.host().write_command(test::command_of(-100.0, 100.0, 100.0)).status);
  driven = contract.backend().device_command();
  const double magnitude = std::sqrt(driven.force_n[0] * driven.force_n[0] + driven.force_n[1] * driven.force_n[1] +
                                     driven.force_n[2] * driven.force_n[2]);
  // The wires round each clamped component toward zero, so they never pass 5 N; the direct device
  // passes the clamped doubles on, which may land a rounding (1e-15 N) above it.
  CHECK_TRUE(magnitude <= 5.0 + 1e-12);
  DOUBLES_EQUAL(5.0, magnitude, 0.005);
  DOUBLES_EQUAL(-driven.force_n[1], driven.force_n[0], 1e-9);  // direction kept

  CHECK_EQUAL(2U, contract.host().counters().commands_clamped);
}

// The limits are the board's (HapticRange), not a number built into the backend: a board that
// allows 2 N and 50 N.mm gets no more, whatever the device itself would take.
void a_boards_lower_limits_are_the_ones_clamped_to(Contract& contract) {
  hal::HapticRange gentle = kRange;
  gentle.force_limit_n = 2.0;
  gentle.torque_limit_nmm = 50.0;
  contract.backend().restart_host(gentle);
  contract.bring_up();
  hal::HapticCommand command = test::command_of(0.0, 0.0, -4.0);
  command.torque_nmm[0] = 100.0;
  CHECK_EQUAL(WriteStatus::Clamped, contract.host().write_command(command).status);
  const sim::DeviceCommand driven = contract.backend().device_command();
  CHECK_TRUE(driven.enable);
  DOUBLES_EQUAL(-2.0, driven.force_n[2], 1e-3);
  DOUBLES_EQUAL(50.0, driven.torque_nmm[0], 0.011);
  CHECK_EQUAL(WriteStatus::Written, contract.host().write_command(test::command_of(0.0, 1.5, 0.0)).status);
  DOUBLES_EQUAL(1.5, contract.backend().device_command().force_n[1], 1e-3);
}

// A NaN or infinity in a command sends zero force with enable off in its place, counted, not latched.
void a_command_that_is_not_finite_sends_zero_force_with_enable_off(Contract& contract) {
  contract.bring_up();
  CHECK_EQUAL(WriteStatus::Written, contract.host().write_command(test::command_of(2.0, 0.0, 0.0)).status);
  CHECK_TRUE(contract.backend().device_command().enable);

  const hal::WriteResult rejected = contract.host().write_command(test::command_of(2.0, std::nan(""), 0.0));
  CHECK_EQUAL(WriteStatus::Rejected, rejected.status);
  CHECK_EQUAL(HapticFault::CommandNotFinite, rejected.reason);
  sim::DeviceCommand driven = contract.backend().device_command();
  CHECK_FALSE(driven.enable);
  DOUBLES_EQUAL(0.0, driven.force_n[0], 0.0);

  hal::HapticCommand infinite_torque = test::command_of(1.0, 0.0, 0.0);
  infinite_torque.torque_nmm[1] = -HUGE_VAL;
  CHECK_EQUAL(WriteStatus::Rejected, contract.host().write_command(infinite_torque).status);
  driven = contract.backend().device_command();
  CHECK_FALSE(driven.enable);
  DOUBLES_EQUAL(0.0, driven.force_n[0], 0.0);
  DOUBLES_EQUAL(0.0, driven.torque_nmm[1], 0.0);

  CHECK_EQUAL(2U, contract.host().counters().commands_rejected);
  CHECK_EQUAL(HapticFault::None, contract.host().latched_fault());
}

// The host heartbeat moves by one with every write, whatever the command and whatever the result
// (short of a Fault), so the device's watchdog never trips on a host that runs.
void every_write_beats_the_host_heartbeat(Contract& contract) {
  if (!contract.backend().carries_host_heartbeat()) {
    // In process the device is the backend itself: there is no host heartbeat to carry, and no
    // device-side watchdog to feed. Every write still goes through.
    CHECK_TRUE(contract.host().write_command(test::command_of(0.0, 0.0, 1.0)).status != WriteStatus::Fault);
    return;
  }
  const hal::HapticCommand writes[] = {
      test::command_of(0.0, 0.0, 0.0, false),      // enable off
      test::command_of(0.0, 0.0, 1.0),             // enable on (Held on PIO before arming: still a beat)
      test::command_of(0.0, 0.0, std::nan("")),   // refused
      test::command_of(50.0, 0.0, 0.0),            // clamped
  };
  std::uint32_t previous = contract.backend().device_command().host_heartbeat;
  for (const hal::HapticCommand& write : writes) {
    CHECK_TRUE(contract.host().write_command(write).status != WriteStatus::Fault);
    const std::uint32_t beat = contract.backend().device_command().host_heartbeat;
    CHECK_EQUAL(previous + 1U, beat);
    previous = beat;
  }
}

}  // namespace

// ---- Each case on each backend ----------------------------------------------------------------------

TEST_GROUP(HapticContractDirect) {
  DirectBackend backend;
  Contract contract{backend};
};
TEST_GROUP(HapticContractPio) {
  PioBackend backend;
  Contract contract{backend};
};
TEST_GROUP(HapticContractCan) {
  CanBackend backend;
  Contract contract{backend};
};

#define HAPTIC_CONTRACT_CASE(name, check)          \
  TEST(HapticContractDirect, name) { check(contract); } \
  TEST(HapticContractPio, name) { check(contract); }    \
  TEST(HapticContractCan, name) { check(contract); }

HAPTIC_CONTRACT_CASE(AFreshReadGivesTheNewSampleOnceAsTheDeviceWroteIt, a_fresh_read_gives_the_new_sample_once)
HAPTIC_CONTRACT_CASE(AReadGivesTheNewestOfSeveralSamples, a_read_gives_the_newest_of_several_samples)
HAPTIC_CONTRACT_CASE(ASilentDeviceReadsStaleThenLostAfterTheWatchdogTime,
                     a_silent_device_reads_stale_then_lost_after_the_watchdog_time)
HAPTIC_CONTRACT_CASE(SamplesWhoseHeartbeatFrozeAreLostAfterTheWatchdogTime,
                     samples_whose_heartbeat_froze_are_lost_after_the_watchdog_time)
HAPTIC_CONTRACT_CASE(AFaultIsLatchedUntilClearedAndRefusedInputIsNot,
                     a_fault_is_latched_until_cleared_and_refused_input_is_not)
HAPTIC_CONTRACT_CASE(SamplesAreAcceptedUpToTheRangeAndRefusedPastIt,
                     samples_are_accepted_up_to_the_range_and_refused_past_it)
HAPTIC_CONTRACT_CASE(ASampleThatIsNotFiniteIsRefusedNamingWhy, a_sample_that_is_not_finite_is_refused_naming_why)
HAPTIC_CONTRACT_CASE(ATornSampleIsRefusedAndTheNextWholeOneGiven, a_torn_sample_is_refused_and_the_next_whole_one_given)
HAPTIC_CONTRACT_CASE(ACommandWithinTheRangeReachesTheDeviceAsGiven,
                     a_command_within_the_range_reaches_the_device_as_given)
HAPTIC_CONTRACT_CASE(ForceAndTorqueAreClampedToTheirLimits, force_and_torque_are_clamped_to_their_limits)
HAPTIC_CONTRACT_CASE(ABoardsLowerLimitsAreTheOnesClampedTo, a_boards_lower_limits_are_the_ones_clamped_to)
HAPTIC_CONTRACT_CASE(ACommandThatIsNotFiniteSendsZeroForceWithEnableOff,
                     a_command_that_is_not_finite_sends_zero_force_with_enable_off)
HAPTIC_CONTRACT_CASE(EveryWriteBeatsTheHostHeartbeat, every_write_beats_the_host_heartbeat)
