// The simulated CY545 chip driven directly (no pty, no wire time): the behaviours of the manual it
// models (cy545_protocol.hpp) — adaptive baud, busy timing, the 3-character receive buffer, the
// mode register's binary format, the reset pin keeping the MMC-4S latches, the user-bit pins.
#include <cstdint>
#include <string>
#include <string_view>

#include "board/sim/sim_facts.hpp"
#include "sim/cy545/cy545_chip.hpp"
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

struct Chip {
  SimulatedMill mill{board::sim::kMillConfig};
  Mmc4sBoard board{mill, board::sim::kMmc4sWiring};
  Cy545Chip chip{board, 0};

  // Every byte of `bytes` arrives at `at_ns`.
  void send(std::string_view bytes, hal::MonotonicNs at_ns) {
    for (const char c : bytes) chip.receive(static_cast<std::uint8_t>(c), at_ns);
  }
  std::string query(std::string_view bytes, hal::MonotonicNs at_ns) {
    send(bytes, at_ns);
    return chip.take_output();
  }
};

}  // namespace

TEST_GROUP(Cy545Chip) {
  Chip c;
};

TEST(Cy545Chip, BytesBeforeTheFirstCarriageReturnAreNoiseUntilItLocksTheBaudRate) {
  c.send("N 5", 0);
  CHECK_FALSE(c.chip.baud_locked());
  LONGS_EQUAL(3, c.chip.counters().bytes_before_baud_lock);
  c.send("\r", 0);
  CHECK_TRUE(c.chip.baud_locked());
  LONGS_EQUAL(0, static_cast<long>(c.chip.step_count()));  // the N 5 before the lock was never a command
  c.send("N 7\r", 0);
  LONGS_EQUAL(7, static_cast<long>(c.chip.step_count()));
}

TEST(Cy545Chip, AMoveStepsAtKOverRAndIsBusyUntilItsLastStep) {
  c.send("\rR 100\rN 10\rG\r", 0);
  CHECK_TRUE(c.chip.activity() == Activity::moving);
  c.chip.advance_to(95 * kMs);
  LONGS_EQUAL(9, c.chip.counters().steps_issued);  // step k at k * 10 ms
  CHECK_TRUE(c.chip.busy());
  CHECK_FALSE(c.chip.cts_ready());
  c.chip.advance_to(100 * kMs);
  LONGS_EQUAL(10, c.chip.counters().steps_issued);
  CHECK_FALSE(c.chip.busy());
  LONGS_EQUAL(10, static_cast<long>(c.chip.position_register()));
}

TEST(Cy545Chip, WhileBusyThreeBytesWaitInTheBufferAndTheRestAreLost) {
  c.send("\rD 10\r", 0);
  c.send("N 12\r", 1 * kMs);  // "N 1" buffered; '2' and CR dropped
  LONGS_EQUAL(3, c.chip.receive_buffer_bytes());
  LONGS_EQUAL(2, c.chip.counters().bytes_dropped_while_busy);
  c.chip.advance_to(10 * kMs);
  // The buffered bytes are read when the delay ends: a line "N 1" waiting for its CR.
  LONGS_EQUAL(0, c.chip.receive_buffer_bytes());
  LONGS_EQUAL(0, static_cast<long>(c.chip.step_count()));
  c.send("\r", 11 * kMs);
  LONGS_EQUAL(1, static_cast<long>(c.chip.step_count()));
}

TEST(Cy545Chip, ABufferedCommandStartsWhenTheMoveEndsNotWhenItArrived) {
  c.send("\rR 100\rN 2\rG\r", 0);  // busy until 20 ms
  c.send("G\r", 5 * kMs);          // two bytes: both fit the buffer
  c.chip.advance_to(20 * kMs);
  CHECK_TRUE(c.chip.activity() == Activity::moving);
  c.chip.advance_to(39 * kMs);
  LONGS_EQUAL(3, c.chip.counters().steps_issued);  // the second move's first step at 30 ms
  c.chip.advance_to(40 * kMs);
  CHECK_FALSE(c.chip.busy());
  LONGS_EQUAL(4, static_cast<long>(c.chip.position_register()));
}

TEST(Cy545Chip, EveryCommandTakesTheChipsCommandTimeWhenOneIsSet) {
  c.send("\r", 0);
  c.chip.set_command_time_ns(Cy545Chip::kCommandTimeNs);
  c.send("N 5\r", 0);
  CHECK_TRUE(c.chip.activity() == Activity::delaying);
  c.chip.advance_to(Cy545Chip::kCommandTimeNs - 1);
  CHECK_TRUE(c.chip.busy());
  c.chip.advance_to(Cy545Chip::kCommandTimeNs);
  CHECK_FALSE(c.chip.busy());
}

TEST(Cy545Chip, ModeBitSevenClearReadsBinaryLetterCountAndLittleEndianData) {
  c.send("\rO 0\r", 0);
  c.send(std::string("A\x03\x01\x02\x03", 5), 0);
  LONGS_EQUAL(0x030201, static_cast<long>(c.chip.position_register()));
  // ASCII now is taken apart as binary: 'N' with a count of ' ' (32) swallows what follows.
  c.send("N 9\r", 0);
  LONGS_EQUAL(0, static_cast<long>(c.chip.step_count()));
  c.chip.power_on_reset();
  c.send("\r", 0);
  STRCMP_EQUAL("O=128\r", c.query("? O\r", 0).c_str());  // only the reset brought ASCII back
}

TEST(Cy545Chip, ModeBitsOtherThanSevenAreStoredAndReportedAndIRestoresThePowerUpMode) {
  c.send("\rO 81H\r", 0);
  STRCMP_EQUAL("O=129\r", c.query("? O\r", 0).c_str());  // still ASCII
  c.send("I\r", 0);
  LONGS_EQUAL(kDefaultMode, static_cast<long>(c.chip.mode()));
}

// The reset pin resets the chip, not the MMC-4S: the selected channel and the general-purpose
// outputs (the spindle) stay latched on the board, while driver enable (a level on user bit 0) drops.
TEST(Cy545Chip, TheResetPinClearsTheChipButTheBoardsLatchesAndTheSpindleStay) {
  c.send("\rR 500\rA 77\r", 0);
  c.send("B 47H\rB 7\r/B 7\r", 0);  // select Y (data 1: the per-line board), drivers enabled
  c.send("B 53H\rB 7\r/B 7\r", 0);  // spindle on (general output 4)
  CHECK_TRUE(c.mill.spindle_on());
  CHECK_TRUE(c.mill.drivers_enabled());
  c.chip.power_on_reset();
  CHECK_FALSE(c.chip.baud_locked());
  LONGS_EQUAL(0, static_cast<long>(c.chip.position_register()));
  LONGS_EQUAL(kDefaultRateStepsPerSecond, static_cast<long>(c.chip.rate()));
  LONGS_EQUAL(0, c.chip.user_bit_latches());
  LONGS_EQUAL(1, c.board.selected_channel().value_or(-1));
  CHECK_TRUE(c.board.general_output(4));
  CHECK_TRUE(c.mill.spindle_on());
  CHECK_FALSE(c.mill.drivers_enabled());
}

TEST(Cy545Chip, PinLevelsShowReadyOnBitSixAndTheInputMuxOnBitOneWhileTheReadStrobeIsOn) {
  c.send("\r", 0);
  c.board.set_general_input(5, true);
  LONGS_EQUAL(0x40, c.chip.pin_levels());
  c.send("B 74H\r", 0);  // address 5, data latch 0, read strobe on
  LONGS_EQUAL(0x40 | 0x34 | 0x02, c.chip.pin_levels());
  c.send("B 15H\r", 0);  // read strobe off: bit 1 reads its own latch again
  LONGS_EQUAL(0x40 | 0x14, c.chip.pin_levels());
  c.send("D 5\r", 0);
  LONGS_EQUAL(0x14, c.chip.pin_levels());  // busy: CTS low
}

TEST(Cy545Chip, PositionQueriesAddTheFaultOffsetModulo24Bits) {
  c.send("\rA 5\r", 0);
  c.chip.set_query_position_offset(-10);
  STRCMP_EQUAL("P=16777211\r", c.query("? P\r", 0).c_str());
  STRCMP_EQUAL("A=16777211\r", c.query("? A\r", 0).c_str());
  LONGS_EQUAL(5, static_cast<long>(c.chip.position_register()));
  STRCMP_EQUAL("", c.chip.take_output().c_str());  // taken once
}

TEST(Cy545Chip, AnAbsoluteMoveComparesPositionsAsUnsigned24BitNumbers) {
  c.send("\rR 1000\rA 16777215\rP 0\r", 0);  // 0 is below the top: 16777215 steps down, not 1 up
  c.chip.advance_to(2 * kMs);
  LONGS_EQUAL(16777213, static_cast<long>(c.chip.position_register()));
  CHECK_TRUE(c.chip.direction_positive());  // P leaves the +/- setting alone
}

TEST(Cy545Chip, TimeNeverGoesBack) {
  c.send("\rR 100\rN 5\rG\r", 0);
  c.chip.advance_to(30 * kMs);
  c.chip.advance_to(10 * kMs);
  LONGS_EQUAL(30 * kMs, c.chip.now_ns());
  LONGS_EQUAL(3, c.chip.counters().steps_issued);
}

TEST(Cy545Chip, ARefusedLineIsIgnoredAndRecordedWithItsReasonAndColumn) {
  c.send("\rN 5\rN x\r", 0);
  LONGS_EQUAL(5, static_cast<long>(c.chip.step_count()));
  LONGS_EQUAL(1, c.chip.counters().malformed_lines);
  CHECK_TRUE(c.chip.last_error().has_value());
  STRCMP_EQUAL("N x", c.chip.last_error()->line.c_str());
  LONGS_EQUAL(2, c.chip.last_error()->column);
  c.send("N 123456789012345678901234567890123\r", 0);  // 35 characters: too long
  LONGS_EQUAL(2, c.chip.counters().malformed_lines);
  LONGS_EQUAL(5, static_cast<long>(c.chip.step_count()));
  STRCMP_EQUAL("", c.chip.take_output().c_str());  // no error reply in ASCII serial mode
}
