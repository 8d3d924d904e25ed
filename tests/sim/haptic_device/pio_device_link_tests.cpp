// PioDeviceLink on a memfd window: it initialises the header, publishes samples as words (micrometres,
// microradians, saturated) and takes each new command once, in physical units, refusing one beyond
// the device's limits.
#include <cstdint>
#include <limits>

#include "hal/pio_shared_memory/seqlock.hpp"
#include "hal/pio_shared_memory/shared_window_layout.hpp"
#include "sim/haptic_device/pio_device_link.hpp"
#include "tests/hal/pio_shared_memory/window_pair.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace pio = hal::pio_shared_memory;

TEST_GROUP(PioDeviceLink) {
  test::WindowPair windows = test::make_device_window();
  pio::SharedWindow& window = windows.device->window();
  sim::PioDeviceLink link{window};

  pio::PoseWords pose() {
    pio::PoseWords words{};
    CHECK_TRUE(pio::seqlock_read(window.pose, words).consistent);
    return words;
  }
  void send(std::uint32_t counter, std::int32_t fz_mn, std::uint32_t heartbeat, bool enable = true) {
    const pio::CommandWords words{counter, {100, -200, fz_mn}, {3000, -4000}, enable ? pio::kCommandEnableBit : 0U, heartbeat};
    pio::seqlock_write(window.command, words);
  }
};

TEST(PioDeviceLink, TheLinkInitialisesTheWindowsHeaderAsTheControllerDoes) {
  LONGS_EQUAL(pio::kWindowMagic, window.header.magic);
  LONGS_EQUAL(pio::kLayoutVersion, window.header.layout_version);
  LONGS_EQUAL(pio::kWindowBytes, window.header.window_bytes);
}

TEST(PioDeviceLink, APublishedSampleIsWrittenInMicrometresAndMicroradiansWithItsCounters) {
  link.publish(hal::HapticSample{{1.2344, -5.0, 0.0006}, {0.0123456, -0.5}, 1234567, 0xABCDEF, 42});
  const pio::PoseWords words = pose();
  LONGS_EQUAL(1234567, words.sample_counter);  // all 32 bits
  LONGS_EQUAL(1234, words.position_um[0]);
  LONGS_EQUAL(-5000, words.position_um[1]);
  LONGS_EQUAL(1, words.position_um[2]);
  LONGS_EQUAL(12346, words.angles_urad[0]);
  LONGS_EQUAL(-500000, words.angles_urad[1]);
  LONGS_EQUAL(0xABCDEF, words.status_bits);
  LONGS_EQUAL(42, words.device_heartbeat);
  LONGS_EQUAL(1, link.counters().poses_written);
}

TEST(PioDeviceLink, PositionsBeyondInt32AreSaturated) {
  link.publish(hal::HapticSample{{1e10, -1e10, 0.0}, {0.0, 0.0}, 1, 0, 1});
  LONGS_EQUAL(std::numeric_limits<std::int32_t>::max(), pose().position_um[0]);
  LONGS_EQUAL(std::numeric_limits<std::int32_t>::lowest(), pose().position_um[1]);
}

TEST(PioDeviceLink, EachNewCommandIsTakenOnceInPhysicalUnits) {
  sim::DeviceCommand out{};
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::None);
  send(9, 2500, 17);
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::New);
  DOUBLES_EQUAL(0.1, out.force_n[0], 1e-12);
  DOUBLES_EQUAL(-0.2, out.force_n[1], 1e-12);
  DOUBLES_EQUAL(2.5, out.force_n[2], 1e-12);
  DOUBLES_EQUAL(3.0, out.torque_nmm[0], 1e-12);  // mN.mm on this wire
  DOUBLES_EQUAL(-4.0, out.torque_nmm[1], 1e-12);
  LONGS_EQUAL(9, out.cycle_counter);
  LONGS_EQUAL(17, out.host_heartbeat);
  CHECK_TRUE(out.enable);
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::None);  // the same command again is nothing new
  send(10, 0, 18, false);
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::New);
  CHECK_FALSE(out.enable);
}

TEST(PioDeviceLink, ACommandBeyondTheDevicesLimitsIsRefusedAndNotApplied) {
  sim::DeviceCommand out{{7.0, 7.0, 7.0}, {7.0, 7.0}, 7, 7, false};
  send(1, pio::kForceLimitMn + 1000, 1);
  CHECK_TRUE(link.poll(out) == sim::CommandPoll::Refused);
  DOUBLES_EQUAL(7.0, out.force_n[2], 0.0);
  LONGS_EQUAL(1, link.counters().commands_out_of_range);
}
