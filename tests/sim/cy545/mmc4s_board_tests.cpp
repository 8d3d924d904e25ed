// The MMC-4S board alone, fed user-bit writes as the chip makes them: the write strobe's rising edge,
// both channel-latching readings, driver enable as a level, the spindle output, the watchdog relay,
// and home switches as real rigs wire them (inverted, bouncing).
#include <cstdint>
#include <vector>

#include "board/sim/sim_facts.hpp"
#include "sim/cy545/cy545_protocol.hpp"
#include "sim/cy545/mmc4s_board.hpp"
#include "sim/mill/simulated_mill.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::sim;
using namespace stencil::sim::cy545;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

// User bits: enable (bit 0), data (bit 1), address (bits 2-4), write strobe (bit 7).
std::uint8_t bits(int address, bool data, bool strobe, bool enable = true) {
  unsigned value = static_cast<unsigned>(address) << kBitAddressLow;
  if (enable) value |= 1u << kBitDriverEnable;
  if (data) value |= 1u << kBitData;
  if (strobe) value |= 1u << kBitWriteStrobe;
  return static_cast<std::uint8_t>(value);
}

struct Board {
  SimulatedMill mill{board::sim::kMillConfig};
  Mmc4sBoard board{mill, board::sim::kMmc4sWiring};
  std::uint8_t latches = 0;

  // Writes `address` = `data` with a strobe pulse (up, then down), as a driver does.
  void latch(int address, bool data, hal::MonotonicNs at_ns = 0) {
    write(bits(address, data, false), at_ns);
    write(bits(address, data, true), at_ns);
    write(bits(address, data, false), at_ns);
  }
  void write(std::uint8_t after, hal::MonotonicNs at_ns) {
    board.on_user_bits_written(latches, after, at_ns);
    latches = after;
  }
};

}  // namespace

TEST_GROUP(Mmc4sBoard) {
  Board b;
};

TEST(Mmc4sBoard, OnlyTheWriteStrobesRisingEdgeLatchesAndAHeldStrobeDoesNotRelatch) {
  b.write(bits(1, true, false), 0);
  CHECK_FALSE(b.board.selected_channel().has_value());  // no strobe yet
  b.write(bits(1, true, true), 0);
  LONGS_EQUAL(1, b.board.selected_channel().value_or(-1));
  b.write(bits(2, true, true), 0);  // address changes under a held strobe
  LONGS_EQUAL(1, b.board.selected_channel().value_or(-1));
  LONGS_EQUAL(1, b.board.channel_selections());
}

TEST(Mmc4sBoard, PerLineLatchingCanSelectTwoChannelsAndThenEveryStepMovesBoth) {
  b.latch(0, true);
  b.latch(1, true);  // X never deselected
  LONGS_EQUAL(2, b.board.selected_channel_count());
  CHECK_FALSE(b.board.selected_channel().has_value());
  const std::int64_t x0 = b.mill.motor_position_steps(Axis::x);
  const std::int64_t y0 = b.mill.motor_position_steps(Axis::y);
  b.board.step_pulse(StepDirection::positive);
  LONGS_EQUAL(x0 + 1, b.mill.motor_position_steps(Axis::x));
  LONGS_EQUAL(y0 + 1, b.mill.motor_position_steps(Axis::y));
  b.latch(0, false);
  LONGS_EQUAL(1, b.board.selected_channel().value_or(-1));
}

TEST(Mmc4sBoard, AddressLatchingSelectsTheAddressedChannelAloneWhateverTheDataBit) {
  b.board.set_channel_latching(ChannelLatching::Address);
  b.latch(0, true);
  b.latch(2, false);
  LONGS_EQUAL(1, b.board.selected_channel_count());
  LONGS_EQUAL(2, b.board.selected_channel().value_or(-1));
}

TEST(Mmc4sBoard, StepsWithNoChannelOrOnTheUnwiredChannelThreeGoNowhereAndAreCounted) {
  b.board.step_pulse(StepDirection::positive);
  b.latch(3, true);
  b.board.step_pulse(StepDirection::positive);
  LONGS_EQUAL(2, b.board.steps_to_no_channel());
}

TEST(Mmc4sBoard, DriverEnableIsALevelAndTheSpindleFollowsGeneralOutputFour) {
  b.write(bits(0, false, false, true), 0);
  CHECK_TRUE(b.mill.drivers_enabled());  // no strobe needed
  b.latch(4, true);
  CHECK_TRUE(b.board.general_output(4));
  CHECK_TRUE(b.mill.spindle_on());
  CHECK_FALSE(b.board.selected_channel().has_value());  // an output is not a channel
  b.write(bits(4, true, false, false), 0);
  CHECK_FALSE(b.mill.drivers_enabled());
  CHECK_TRUE(b.mill.spindle_on());  // the output stays latched
  b.latch(4, false);
  CHECK_FALSE(b.mill.spindle_on());
}

TEST(Mmc4sBoard, TheWatchdogRelayCutsSpindleAndDriversWhenTheHeartbeatStopsAndClosesAtItsNextChange) {
  b.board.arm_watchdog_relay(5, 10 * kMs, 0);
  b.latch(4, true, 0);
  b.latch(5, true, 5 * kMs);  // a heartbeat
  b.board.advance_to(15 * kMs);
  CHECK_TRUE(b.board.watchdog_relay_closed());
  b.board.advance_to(15 * kMs + 1);
  CHECK_FALSE(b.board.watchdog_relay_closed());
  CHECK_FALSE(b.mill.spindle_on());
  CHECK_FALSE(b.mill.drivers_enabled());
  b.latch(5, true, 20 * kMs);  // the same level again: no change, no heartbeat
  CHECK_FALSE(b.board.watchdog_relay_closed());
  b.latch(5, false, 21 * kMs);
  CHECK_TRUE(b.board.watchdog_relay_closed());
  CHECK_TRUE(b.mill.spindle_on());
  CHECK_TRUE(b.mill.drivers_enabled());
}

TEST(Mmc4sBoard, HomeInputsReadTheSwitchAndAnInvertedRigReadsItTheOtherWay) {
  const std::int64_t edge = board::sim::kMillConfig.axes[0].home_switch_edge_steps;
  b.mill.place_axis(Axis::x, edge - 1, StepDirection::positive);
  CHECK_TRUE(b.board.input_level(0));
  b.mill.place_axis(Axis::x, edge, StepDirection::positive);
  CHECK_FALSE(b.board.input_level(0));
  b.board.set_home_switches_inverted(true);
  CHECK_TRUE(b.board.input_level(0));
  CHECK_FALSE(b.board.input_level(3));  // channel 3 has no switch
}

TEST(Mmc4sBoard, ABouncingSwitchChattersNearItsEdgeOnlyAndTheSameWayEveryRun) {
  const std::int64_t edge = board::sim::kMillConfig.axes[0].home_switch_edge_steps;
  const auto reads = [edge](std::int64_t from_edge) {
    Board fresh;
    fresh.board.set_home_switch_bounce(5);
    fresh.mill.place_axis(Axis::x, edge + from_edge, StepDirection::positive);
    std::vector<bool> levels;
    for (int i = 0; i < 32; ++i) levels.push_back(fresh.board.input_level(0));
    return levels;
  };
  const std::vector<bool> near = reads(2);
  CHECK_TRUE(near == reads(2));  // deterministic
  int high = 0;
  for (const bool level : near) high += level ? 1 : 0;
  CHECK_TRUE(high > 0 && high < 32);  // chatters
  for (const bool level : reads(5)) CHECK_FALSE(level);  // just outside the band: open, steadily
}
