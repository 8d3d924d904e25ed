// The fake CY545 over a real pty on a virtual clock: every command's effect, timing, buffer, mux, homing.
#include <cstdint>
#include <string>

#include "sim/cy545/move_profile.hpp"
#include "tests/sim/cy545/fake_cy545_bench.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using namespace stencil::sim::cy545;
using namespace stencil::sim::cy545::test;

TEST_GROUP(FakeCy545) {
  FakeCy545Bench bench;
  std::int64_t x0 = 0;
  std::int64_t y0 = 0;
  std::int64_t z0 = 0;
  void setup() override {
    x0 = bench.mill.axis_position_steps(Axis::x);
    y0 = bench.mill.axis_position_steps(Axis::y);
    z0 = bench.mill.axis_position_steps(Axis::z);
  }
};

TEST(FakeCy545, IgnoresEverythingBeforeTheFirstCarriageReturn) {
  CHECK_TRUE(bench.send("N 5"));
  CHECK_FALSE(bench.fake.chip().baud_locked());
  CHECK_TRUE(bench.send("\r"));
  CHECK_TRUE(bench.fake.chip().baud_locked());
  LONGS_EQUAL(3, bench.fake.chip().counters().bytes_before_baud_lock);
  STRCMP_EQUAL("N=0\r", bench.query("? N\r").c_str());
  STRCMP_EQUAL("N=5\r", bench.query("N 5\r? N\r").c_str());
}

TEST(FakeCy545, QueryRepliesAreTheLetterEqualsDecimalDigitsAndCarriageReturn) {
  CHECK_TRUE(bench.send("\r"));
  STRCMP_EQUAL("P=0\r", bench.query("? P\r").c_str());
  STRCMP_EQUAL("A=16777215\r", bench.query("A 16777215\r? A\r").c_str());
  STRCMP_EQUAL("P=16777215\r", bench.query("? P\r").c_str());
  STRCMP_EQUAL("R=1000\r", bench.query("? R\r").c_str());
  STRCMP_EQUAL("F=1000\r", bench.query("? F\r").c_str());
  STRCMP_EQUAL("S=0\r", bench.query("? S\r").c_str());
  STRCMP_EQUAL("O=128\r", bench.query("? O\r").c_str());  // the manual's power-up mode: ASCII
  STRCMP_EQUAL("B=64\r", bench.query("? B\r").c_str());  // only CTS (bit 6): ready
  LONGS_EQUAL(8, bench.fake.chip().counters().replies);
}

// Issue 18, item 2: the driver sent "O 0" at start-up, which clears the mode register's bit 7 and
// puts the real chip into binary command mode (manual, chapter 9): every ASCII command after it is
// read as a binary letter, count and data, and no query is answered.
TEST(FakeCy545, ModeZeroPutsTheChipInBinaryModeWhereAsciiCommandsAreNotUnderstood) {
  CHECK_TRUE(bench.send("\r"));
  CHECK_TRUE(bench.send("O 0\r"));
  LONGS_EQUAL(0, static_cast<long>(bench.fake.chip().mode()));
  // "? P\r" in binary is '?' with a data count of 32 (the space): it waits for 32 more bytes.
  STRCMP_EQUAL("", bench.query("? P\r").c_str());
  CHECK_TRUE(bench.send("N 5\r"));
  LONGS_EQUAL(0, static_cast<long>(bench.fake.chip().step_count()));
  LONGS_EQUAL(0, bench.fake.chip().counters().replies);
}

TEST(FakeCy545, BinaryCommandsTakeLetterCountAndLittleEndianDataAndModeBit7BringsAsciiBack) {
  CHECK_TRUE(bench.send("\r"));
  CHECK_TRUE(bench.send("O 0\r"));
  CHECK_TRUE(bench.send(std::string("N\x03\x11\x22\x33", 5)));  // N 332211H
  LONGS_EQUAL(0x332211, static_cast<long>(bench.fake.chip().step_count()));
  CHECK_TRUE(bench.send(std::string("R\x02\x01\x02", 4)));  // a wrong count: refused, counted
  LONGS_EQUAL(1, bench.fake.chip().counters().malformed_lines);
  CHECK_TRUE(bench.send(std::string("O\x01\x80", 3)));  // back to ASCII
  STRCMP_EQUAL("N=3351057\r", bench.query("? N\r").c_str());
}

TEST(FakeCy545, InitialiseRestoresTheAsciiMode) {
  CHECK_TRUE(bench.send("\r"));
  CHECK_TRUE(bench.send("O 81H\r"));
  STRCMP_EQUAL("O=128\r", bench.query("I\r? O\r").c_str());
}

TEST(FakeCy545, DecimalAndHexArgumentsSetTheSameValue) {
  CHECK_TRUE(bench.send("\r"));
  STRCMP_EQUAL("N=135\r", bench.query("N 135\r? N\r").c_str());
  STRCMP_EQUAL("N=135\r", bench.query("N 87H\r? N\r").c_str());
  STRCMP_EQUAL("N=171\r", bench.query("N 0ABH\r? N\r").c_str());
  STRCMP_EQUAL("N=171\r", bench.query("N ABH\rN 0AB\r? N\r").c_str());  // both refused
  LONGS_EQUAL(2, bench.fake.chip().counters().malformed_lines);
}

TEST(FakeCy545, TwentyFourBitArgumentsAreLimited) {
  CHECK_TRUE(bench.send("\r"));
  STRCMP_EQUAL("N=16777215\r", bench.query("N 16777215\r? N\r").c_str());
  STRCMP_EQUAL("N=16777215\r", bench.query("N 16777216\r? N\r").c_str());
  STRCMP_EQUAL("A=16777215\r", bench.query("A 0FFFFFFH\r? A\r").c_str());
  STRCMP_EQUAL("A=16777215\r", bench.query("A 1000000H\r? A\r").c_str());
  LONGS_EQUAL(2, bench.fake.chip().counters().malformed_lines);
}

TEST(FakeCy545, RelativeMoveOfNStepsAtRateRTakesNOverRSeconds) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("R 500\rN 1000\r+\rG\r"));
  CHECK_TRUE(bench.fake.chip().busy());
  CHECK_FALSE(bench.fake.chip().cts_ready());
  bench.advance_to_ns(2000 * kMs - 1);
  CHECK_TRUE(bench.fake.chip().busy());
  LONGS_EQUAL(999, bench.fake.chip().counters().steps_issued);
  bench.advance_to_ns(2000 * kMs);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(1000, bench.fake.chip().counters().steps_issued);
  LONGS_EQUAL(x0 + 1000, bench.mill.axis_position_steps(Axis::x));
  STRCMP_EQUAL("P=1000\r", bench.query("? P\r").c_str());
  // Each step falls at k/R: step 250 at 0.5 s.
  CHECK_TRUE(bench.send("G\r"));
  bench.advance_to_ns(2500 * kMs - 1);
  LONGS_EQUAL(1249, bench.fake.chip().counters().steps_issued);
  bench.advance_to_ns(2500 * kMs);
  LONGS_EQUAL(1250, bench.fake.chip().counters().steps_issued);
}

TEST(FakeCy545, MinusDirectionStepsNegativeAndTheMillTakesUpItsBacklash) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("A 5000\r-\rN 100\rG\r"));
  bench.advance_ms(100);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(x0 - (100 - 80), bench.mill.axis_position_steps(Axis::x));
  STRCMP_EQUAL("P=4900\r", bench.query("? P\r").c_str());
}

TEST(FakeCy545, PositionRegisterWrapsModulo24Bits) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("-\rN 1\rG\r"));
  bench.advance_ms(1);
  STRCMP_EQUAL("P=16777215\r", bench.query("? P\r").c_str());
  CHECK_TRUE(bench.send("+\rN 2\rG\r"));
  bench.advance_ms(2);
  STRCMP_EQUAL("P=1\r", bench.query("? P\r").c_str());
}

TEST(FakeCy545, AbsoluteMoveStepsTheDifferenceAndKeepsTheRelativeDirection) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("A 1000\r-\rP 1500\r"));
  bench.advance_ms(499);
  CHECK_TRUE(bench.fake.chip().busy());
  bench.advance_ms(1);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(x0 + 500, bench.mill.axis_position_steps(Axis::x));
  CHECK_TRUE(bench.send("P 1200\r"));
  bench.advance_ms(300);
  STRCMP_EQUAL("P=1200\r", bench.query("? P\r").c_str());
  LONGS_EQUAL(x0 + 500 - (300 - 80), bench.mill.axis_position_steps(Axis::x));
  CHECK_FALSE(bench.fake.chip().direction_positive());  // still the '-' sent before
  CHECK_TRUE(bench.send("P 1200\r"));                    // already there: nothing to do
  CHECK_FALSE(bench.fake.chip().busy());
}

TEST(FakeCy545, ChannelSwitchingMovesOnlyTheSelectedAxis) {
  CHECK_TRUE(bench.start_on_channel(1));
  CHECK_TRUE(bench.send("N 50\rG\r"));
  bench.advance_ms(50);
  LONGS_EQUAL(x0, bench.mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(y0 + 50, bench.mill.axis_position_steps(Axis::y));
  LONGS_EQUAL(z0, bench.mill.axis_position_steps(Axis::z));
  // Z: address 2, strobe up and down.
  CHECK_TRUE(bench.send("B 49H\rB 7\r/B 7\rN 70\rG\r"));
  CHECK_EQUAL(2, bench.fake.board().selected_channel().value_or(-1));
  bench.advance_ms(70);
  LONGS_EQUAL(x0, bench.mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(y0 + 50, bench.mill.axis_position_steps(Axis::y));
  LONGS_EQUAL(z0 + 70, bench.mill.axis_position_steps(Axis::z));
  // Changing the address without a new strobe edge does not change the channel.
  CHECK_TRUE(bench.send("B 41H\rN 10\rG\r"));
  bench.advance_ms(10);
  LONGS_EQUAL(x0, bench.mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(z0 + 80, bench.mill.axis_position_steps(Axis::z));
  // A rising edge latches address 0; moving the address to 1 with the strobe held high does not relatch.
  CHECK_TRUE(bench.send("B 7\rB 45H\rB 7\rN 10\rG\r"));
  bench.advance_ms(10);
  CHECK_EQUAL(0, bench.fake.board().selected_channel().value_or(-1));
  LONGS_EQUAL(x0 + 10, bench.mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(y0 + 50, bench.mill.axis_position_steps(Axis::y));
}

TEST(FakeCy545, StepsGoNowhereBeforeAChannelIsSelectedOrWithDriversDisabled) {
  CHECK_TRUE(bench.send("\rB 0\rN 20\rG\r"));  // drivers on (bit 0), no channel yet
  CHECK_TRUE(bench.mill.drivers_enabled());
  bench.advance_ms(20);
  LONGS_EQUAL(20, bench.fake.board().steps_to_no_channel());
  CHECK_TRUE(bench.send("B 7\r/B 7\r/B 0\rG\r"));  // channel 0, then drivers off
  bench.advance_ms(20);
  CHECK_FALSE(bench.mill.drivers_enabled());
  LONGS_EQUAL(x0, bench.mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(20, bench.mill.steps_ignored_while_disabled());
  STRCMP_EQUAL("P=40\r", bench.query("? P\r").c_str());  // the chip counted them all the same
}

TEST(FakeCy545, BitCommandsFollowTheManualsCoding) {
  CHECK_TRUE(bench.send("\r"));
  STRCMP_EQUAL("B=68\r", bench.query("B 2\r? B\r").c_str());       // bit 2 + CTS
  STRCMP_EQUAL("B=64\r", bench.query("/B 2\r? B\r").c_str());
  STRCMP_EQUAL("B=72\r", bench.query("B 23H\r? B\r").c_str());     // 20H-3FH = 00H-1FH: bit 3
  STRCMP_EQUAL("B=64\r", bench.query("B 13H\r? B\r").c_str());     // clear bit 3
  STRCMP_EQUAL("B=64\r", bench.query("B 6\r? B\r").c_str());       // bit 6 is the chip's CTS
  STRCMP_EQUAL("B=192\r", bench.query("B 7\r? B\r").c_str());
  STRCMP_EQUAL("B=221\r", bench.query("B 5DH\r? B\r").c_str());    // bits 0-5 := 011101, bit 7 kept
  STRCMP_EQUAL("B=197\r", bench.query("B 87H\r? B\r").c_str());    // AND bits 0-5 with 000111
  STRCMP_EQUAL("B=199\r", bench.query("B 0C2H\r? B\r").c_str());   // OR bits 0-5 with 000010
  UNSIGNED_LONGS_EQUAL(0x87, bench.fake.chip().user_bit_latches());
  CHECK_TRUE(bench.send("B 0AH\r"));                                // data-bus bit 2: stored only
  UNSIGNED_LONGS_EQUAL(0x04, bench.fake.chip().data_bus_latches());
  CHECK_TRUE(bench.send("/B 0AH\r"));
  UNSIGNED_LONGS_EQUAL(0x00, bench.fake.chip().data_bus_latches());
  CHECK_TRUE(bench.mill.drivers_enabled());                    // bit 0 is the driver enable
}

TEST(FakeCy545, ReadStrobePutsTheSelectedHomeSensorOnBitOne) {
  bench.mill.place_axis(Axis::y, -10, StepDirection::negative);     // Y inside its switch
  CHECK_TRUE(bench.send("\rB 61H\r"));                               // enable, address 0 (X), read strobe
  STRCMP_EQUAL("B=97\r", bench.query("? B\r").c_str());             // X open: bit 1 = 0
  STRCMP_EQUAL("B=103\r", bench.query("B 65H\r? B\r").c_str());     // address 1 (Y): bit 1 = 1
  STRCMP_EQUAL("B=69\r", bench.query("B 45H\r? B\r").c_str());      // strobe off: bit 1 = its latch
}

TEST(FakeCy545, HomeSeekStepsAwayThenStopsOnTheSwitchEdgeAndZeroesThePosition) {
  bench.mill.place_axis(Axis::x, 3000, StepDirection::positive);
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("A 777\rH 11H\r"));
  // Away (-): 80 slack + 3001 to reach -1 (closed); back (+): 80 slack + 1 to reach 0 (open). At F.
  const std::int64_t steps = 80 + 3001 + 80 + 1;
  bench.advance_to_ns(steps * kMs - 1);
  CHECK_TRUE(bench.fake.chip().busy());
  bench.advance_to_ns(steps * kMs);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(0, bench.mill.axis_position_steps(Axis::x));
  CHECK_FALSE(bench.mill.home_switch_closed(Axis::x));
  STRCMP_EQUAL("P=0\r", bench.query("? P\r").c_str());
  LONGS_EQUAL(steps, bench.fake.chip().counters().steps_issued);
  LONGS_EQUAL(y0, bench.mill.axis_position_steps(Axis::y));
}

TEST(FakeCy545, HomeSeekFromInsideTheSwitchOnlyStepsPositive) {
  bench.mill.place_axis(Axis::z, -500, StepDirection::negative);
  CHECK_TRUE(bench.start_on_channel(2));
  CHECK_TRUE(bench.send("F 2000\rH 11H\r"));
  bench.advance_ms((80 + 500) / 2);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(0, bench.mill.axis_position_steps(Axis::z));
  LONGS_EQUAL(80 + 500, bench.fake.chip().counters().steps_issued);
  UNSIGNED_LONGS_EQUAL(0, bench.fake.chip().position_register());
}

TEST(FakeCy545, WaitForBitIsBusyUntilTheBitMatches) {
  CHECK_TRUE(bench.send("\rB 71H\rW 1\r"));   // read strobe on address 4: general-purpose input 4
  CHECK_TRUE(bench.fake.chip().busy());
  bench.advance_ms(500);
  CHECK_TRUE(bench.fake.chip().busy());
  bench.fake.board().set_general_input(4, true);
  bench.advance_ms(1);
  CHECK_FALSE(bench.fake.chip().busy());
  CHECK_TRUE(bench.send("W 1\r"));            // already matching: done at once
  CHECK_FALSE(bench.fake.chip().busy());
  CHECK_TRUE(bench.send("W 11H\r"));
  CHECK_TRUE(bench.fake.chip().busy());
}

TEST(FakeCy545, DelayIsBusyForItsMilliseconds) {
  CHECK_TRUE(bench.send("\rD 250\r"));
  bench.advance_to_ns(250 * kMs - 1);
  CHECK_TRUE(bench.fake.chip().busy());
  bench.advance_to_ns(250 * kMs);
  CHECK_FALSE(bench.fake.chip().busy());
  CHECK_TRUE(bench.send("D 0\r"));
  CHECK_FALSE(bench.fake.chip().busy());
}

TEST(FakeCy545, InitialiseResetsRegistersAndUserBitsButNotTheBoardLatches) {
  CHECK_TRUE(bench.start_on_channel(1));
  CHECK_TRUE(bench.send("A 99\rN 5\r-\rR 300\rF 200\rS 9\rO 83H\rI\r"));
  const Cy545Chip& chip = bench.fake.chip();
  UNSIGNED_LONGS_EQUAL(0, chip.position_register());
  UNSIGNED_LONGS_EQUAL(0, chip.step_count());
  CHECK_TRUE(chip.direction_positive());
  UNSIGNED_LONGS_EQUAL(1000, chip.rate());
  UNSIGNED_LONGS_EQUAL(1000, chip.first_rate());
  UNSIGNED_LONGS_EQUAL(0, chip.slope());
  UNSIGNED_LONGS_EQUAL(0x80, chip.mode());  // ASCII, as after power-up
  UNSIGNED_LONGS_EQUAL(0, chip.user_bit_latches());
  CHECK_FALSE(bench.mill.drivers_enabled());
  CHECK_EQUAL(1, bench.fake.board().selected_channel().value_or(-1));
}

TEST(FakeCy545, RateFirstRateSlopeAndModeAreStoredAndQueried) {
  CHECK_TRUE(bench.send("\r"));
  STRCMP_EQUAL("R=900\r", bench.query("R 900\r? R\r").c_str());
  STRCMP_EQUAL("F=200\r", bench.query("F 0C8H\r? F\r").c_str());
  STRCMP_EQUAL("S=200\r", bench.query("S 200\r? S\r").c_str());
  STRCMP_EQUAL("O=133\r", bench.query("O 85H\r? O\r").c_str());  // bit 7 kept: still ASCII
}

TEST(FakeCy545, SlopeRampsFromTheFirstRateAndLengthensTheMove) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("R 1000\rF 100\rS 200\rN 2000\rG\r"));
  // a = 3906 * 25 / 56 = 1743.75 steps/s^2; ramp 0.516 s each way over 283.9 steps; cruise 1.432 s.
  const MoveProfile profile(2000, 1000, 100, 200);
  CHECK_TRUE(profile.ramped());
  const double seconds = static_cast<double>(profile.duration_ns()) * 1e-9;
  DOUBLES_EQUAL(2.0 * 900.0 / 1743.75 + (2000.0 - 990000.0 / 1743.75) / 1000.0, seconds, 1e-6);
  CHECK_TRUE(seconds > 2.0);
  bench.advance_to_ns(profile.duration_ns() - 1);
  CHECK_TRUE(bench.fake.chip().busy());
  LONGS_EQUAL(1999, bench.fake.chip().counters().steps_issued);
  bench.advance_to_ns(profile.duration_ns());
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(x0 + 2000, bench.mill.axis_position_steps(Axis::x));
  // The first step comes at the first rate's pace (~1/100 s), not the slew rate's.
  CHECK_TRUE(profile.step_offset_ns(1) > 9 * kMs);
  // A short move never reaches the slew rate: a symmetric triangle.
  const MoveProfile short_move(100, 1000, 100, 200);
  const std::int64_t half = short_move.step_offset_ns(50);
  CHECK_TRUE(short_move.duration_ns() - 2 * half <= 1 && 2 * half - short_move.duration_ns() <= 1);
}

TEST(FakeCy545, BytesWhileBusyFillTheThreeCharacterBufferAndTheRestIsDropped) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("N 1000\rG\r"));
  CHECK_TRUE(bench.fake.chip().busy());
  UNSIGNED_LONGS_EQUAL(0, bench.fake.chip().pin_levels() & 0x40);   // CTS dropped
  bench.advance_ms(10);
  CHECK_TRUE(bench.send("N 77\r"));                                  // "N 7" kept, "7\r" lost
  LONGS_EQUAL(3, bench.fake.chip().receive_buffer_bytes());
  LONGS_EQUAL(2, bench.fake.chip().counters().bytes_dropped_while_busy);
  CHECK_TRUE(bench.send("? P\r"));                                   // lost entirely: no reply
  LONGS_EQUAL(6, bench.fake.chip().counters().bytes_dropped_while_busy);
  STRCMP_EQUAL("", bench.client.read_for(50).c_str());
  bench.advance_ms(990);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(0, bench.fake.chip().receive_buffer_bytes());
  UNSIGNED_LONGS_EQUAL(0x40, bench.fake.chip().pin_levels() & 0x40);
  // The buffered "N 7" waits for its CR like any line.
  STRCMP_EQUAL("N=7\r", bench.query("\r? N\r").c_str());
}

TEST(FakeCy545, BufferedCommandRunsWhenTheMoveEndsAndItsTimeStartsThen) {
  CHECK_TRUE(bench.start_on_channel(0));
  CHECK_TRUE(bench.send("N 100\rG"));
  CHECK_TRUE(bench.send("\rG\r"));     // CR starts the move; "G\r" waits in the buffer
  LONGS_EQUAL(2, bench.fake.chip().receive_buffer_bytes());
  bench.advance_ms(150);               // first move ends at 100 ms, the second starts then
  CHECK_TRUE(bench.fake.chip().busy());
  LONGS_EQUAL(150, bench.fake.chip().counters().steps_issued);
  bench.advance_ms(50);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(x0 + 200, bench.mill.axis_position_steps(Axis::x));
}

TEST(FakeCy545, MalformedLinesAreIgnoredWithoutAReplyAndCounted) {
  CHECK_TRUE(bench.send("\rN 9\r"));
  CHECK_TRUE(bench.send("n 5\rN5\rG 5\rN 5 6\r/N 5\r? Q\r?\rN 1A\rN 5\n\r"));
  LONGS_EQUAL(9, bench.fake.chip().counters().malformed_lines);
  CHECK_TRUE(bench.send("X\rC\r"));
  LONGS_EQUAL(2, bench.fake.chip().counters().unsupported_commands);
  CHECK_TRUE(bench.fake.chip().last_error().has_value());
  STRCMP_EQUAL("C", bench.fake.chip().last_error()->line.c_str());
  CHECK_FALSE(bench.fake.chip().busy());
  // Nothing was sent back for any of them, and N is untouched.
  STRCMP_EQUAL("N=9\r", bench.query("? N\r").c_str());
}

TEST(FakeCy545, LineFeedAfterCarriageReturnSpoilsTheNextCommand) {
  CHECK_TRUE(bench.send("\r"));
  STRCMP_EQUAL("N=4\r", bench.query("N 4\r\nN 3\r? N\r").c_str());
  LONGS_EQUAL(1, bench.fake.chip().counters().malformed_lines);
  STRCMP_EQUAL("\nN 3", bench.fake.chip().last_error()->line.c_str());
}

TEST(FakeCy545, SpindleFollowsGeneralPurposeOutputFourWithoutTouchingTheChannel) {
  CHECK_TRUE(bench.start_on_channel(1));
  CHECK_TRUE(bench.send("B 53H\rB 7\r/B 7\r"));
  CHECK_TRUE(bench.mill.spindle_on());
  CHECK_TRUE(bench.fake.board().general_output(4));
  CHECK_EQUAL(1, bench.fake.board().selected_channel().value_or(-1));
  CHECK_TRUE(bench.send("B 51H\rB 7\r/B 7\r"));
  CHECK_FALSE(bench.mill.spindle_on());
}

TEST(FakeCy545, TheByteSequencesDocumentedForTheDriverWork) {
  bench.mill.place_axis(Axis::y, 1000, StepDirection::positive);
  CHECK_TRUE(bench.send("\r"));
  // Select Y, move 100 steps +.
  CHECK_TRUE(bench.send("B 45H\rB 7\r/B 7\rN 100\r+\rG\r"));
  bench.advance_ms(100);
  LONGS_EQUAL(1100, bench.mill.axis_position_steps(Axis::y));
  // Home Y: read strobe on with Y's address, seek bit 1 low.
  CHECK_TRUE(bench.send("B 65H\rH 11H\r"));
  bench.advance_ms(10'000);
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(0, bench.mill.axis_position_steps(Axis::y));
  STRCMP_EQUAL("P=0\r", bench.query("? P\r").c_str());
  // After homing a + move moves at once.
  CHECK_TRUE(bench.send("B 45H\rN 640\r+\rG\r"));
  bench.advance_ms(640);
  DOUBLES_EQUAL(1.0, bench.mill.axis_position_mm(Axis::y), 1e-12);
  STRCMP_EQUAL("P=640\r", bench.query("? P\r").c_str());
  LONGS_EQUAL(x0, bench.mill.axis_position_steps(Axis::x));
  LONGS_EQUAL(z0, bench.mill.axis_position_steps(Axis::z));
  // Spindle on and off.
  CHECK_TRUE(bench.send("B 53H\rB 7\r/B 7\r"));
  CHECK_TRUE(bench.mill.spindle_on());
  CHECK_TRUE(bench.send("B 51H\rB 7\r/B 7\r"));
  CHECK_FALSE(bench.mill.spindle_on());
  LONGS_EQUAL(0, bench.fake.chip().counters().malformed_lines);
}

// Issue 18, item 7: with no CTS (it needs a mode bit the driver never sets, manual chapter 16) a
// host that sends commands back to back overruns the three-character buffer while the chip
// executes the one before: the channel select's strobe commands are lost.
TEST(FakeCy545, CommandsSentBackToBackOverrunTheBufferWhileTheChipTakesEachOne) {
  Cy545Chip& chip = bench.fake.chip();
  chip.set_command_time_ns(Cy545Chip::kCommandTimeNs);
  constexpr stencil::hal::MonotonicNs kByte = 173'611;  // ten bits at 57600 baud
  const std::string commands = "\rB 45H\rB 7\r/B 7\r";
  stencil::hal::MonotonicNs at = 0;
  for (const char c : commands) {
    chip.receive(static_cast<std::uint8_t>(c), at += kByte);
  }
  bench.advance_to_ns(at + 10 * kMs);
  CHECK(chip.counters().bytes_dropped_while_busy > 0);
  CHECK_FALSE(bench.fake.board().selected_channel().has_value());
}

TEST(FakeCy545, CommandsPacedByHalfAMillisecondAreAllTaken) {
  Cy545Chip& chip = bench.fake.chip();
  chip.set_command_time_ns(Cy545Chip::kCommandTimeNs);
  constexpr stencil::hal::MonotonicNs kByte = 173'611;
  stencil::hal::MonotonicNs at = 0;
  for (const std::string command : {"\r", "B 45H\r", "B 7\r", "/B 7\r"}) {
    for (const char c : command) {
      chip.receive(static_cast<std::uint8_t>(c), at += kByte);
    }
    at += 500'000;  // the driver's settle
  }
  bench.advance_to_ns(at + 10 * kMs);
  LONGS_EQUAL(0, chip.counters().bytes_dropped_while_busy);
  CHECK_EQUAL(1, bench.fake.board().selected_channel().value_or(-1));
}
