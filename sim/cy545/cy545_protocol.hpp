// The CY545 byte protocol and MMC-4S user-bit wiring exactly as the fake (sim/cy545) implements them:
// the contract a CY545 driver must meet to run against the fake (and, where marked, an assumption).
#pragma once

#include <cstdint>

// ============================================================================================
// Serial framing
// --------------------------------------------------------------------------------------------
// * A command is: one upper-case letter (or '+', '-', '?'), then for commands with arguments ONE space
//   and the arguments separated by spaces and/or commas, then a carriage return (0x0D). No line feed:
//   a 0x0A byte is an ordinary (illegal) character, so "N 5\r\n" makes the NEXT line malformed.
//   Trailing spaces before the CR are tolerated. The prefix '/' is legal only before 'B'.
// * Numbers: decimal digits ("135"), or hex digits with an 'H' suffix and a leading decimal digit
//   ("87H", "0ABH"; "ABH" and "0AB" are malformed). Upper-case hex only.
// * An empty line (a bare CR) does nothing and is not an error.
// * Adaptive baud: after power-up (and after reset()) the chip ignores every byte until the first CR,
//   which "locks the baud rate" (a pty has no baud rate; the lock is modelled so that a driver's
//   start-up of sending CRs until a query answers is exercised). Bytes before the lock are counted.
// * The fake has no character time: bytes it reads from the pty in one service arrive at that instant.
//
// Busy and the input buffer
// --------------------------------------------------------------------------------------------
// * G, P, H, W and D execute for a time (below); every other command completes instantly.
// * While a command executes the chip is busy: CTS (user bit 6) reads 0, and the chip reads no input.
//   Bytes arriving meanwhile go to the three-character receive buffer; the 4th and later bytes are
//   DROPPED and counted. When the command ends the buffered bytes are parsed first, as if just sent.
//   So a driver must not send while busy: on a pty (no modem lines) it paces each command by its
//   computed duration plus a margin, then confirms with a query.
//
// Malformed commands
// --------------------------------------------------------------------------------------------
// The manual gives no error reply in ASCII serial mode, so the fake sends NOTHING for a malformed or
// unsupported line: it ignores the whole line, counts it (Cy545Counters::malformed_lines or
// unsupported_commands) and records the reason (Cy545Chip::last_error()). Malformed: lower-case or
// unknown first character, missing space after the letter, bad number, wrong argument count, value out
// of range, '/' before anything but B, a line longer than 32 characters. Unsupported: real CY545
// commands the fake does not implement (C E J L Q T U V X Y Z 0 [ "): counted, ignored.
//
// Commands (arguments and what the fake does)
// --------------------------------------------------------------------------------------------
//  A pos24   set the position register (0..16777215) without moving.
//  N num24   set the step count for relative moves (0..16777215).
//  +  -      direction for relative moves: + is CW = positive motor steps, - is CCW = negative.
//  G         relative move: N steps in the +/- direction on the selected channel. Busy until done.
//  P pos24   absolute move to pos24: compares with the position register as UNSIGNED 24-bit numbers;
//            target > position steps +, target < position steps -. Does not change the +/- setting.
//  R rate    slew rate, ASSUMPTION: in steps per second, 1..27000 (the real chip takes a byte that
//            indexes its 12 MHz rate table; the fake takes the rate itself so that timing is N/R).
//  F rate    first (start) rate, steps per second, 1..27000.
//  S slope   0..255. With S > 0 and F < R a move ramps F -> R -> F at the manual's approximate
//            acceleration a = 3906 * 25 / (256 - S) steps/s^2; otherwise every step is at R.
//  B bit     user bits, per the manual's coding (after '/' XORs the argument with 10H):
//              00H-07H set user bit n      10H-17H clear user bit n
//              08H-0FH / 18H-1FH set/clear a data-bus bit (stored, no effect)
//              20H-3FH same as 00H-1FH     40H-7FH write bits 0-5 at once from the low 6 bits
//              80H-0BFH AND bits 0-5 with the low 6 bits   0C0H-0FFH OR bits 0-5 with the low 6 bits
//            User bit 6 is the chip's busy/CTS output: writes to it are ignored.
//  H bit     seek home on a bit: bit = 0-7 matches when that bit reads 1, 10H-17H when it reads 0.
//            Manual's algorithm: if the bit matches at the start, step - until it does not; then step +
//            until it matches; stop and set the position register to 0. Steps at the first rate F, one
//            every 1/F s, no ramp. Gives up (position unchanged) after 16777215 steps in one phase.
//  W bit     wait until the bit matches (same coding as H). Busy meanwhile.
//  I         initialise: position 0, N 0, direction +, R and F back to 1000 steps/s, S 0, mode 80H, user
//            bits 0-5 and 7 cleared (drivers disabled). The MMC-4S latches (channel, outputs) keep
//            their state: they are on the board, not in the chip.
//  O mode    mode register 0..255 (manual, chapter 9 "Operating Mode Command"): power-up and I leave
//            it 80H, ASCII commands with standard serial query output. Bit 7 selects the command
//            format: set = ASCII, CLEAR = BINARY (chapter 4 "Binary Command Format": the letter, a
//            binary count of data bytes, the data least significant byte first). After "O 0" the fake
//            parses every following byte in that format, as the chip does: an ASCII "? P\r" is the
//            letter '?' with a count of 32 (the space) and swallows the next 32 bytes; only a reset
//            (power-up) or a well-formed binary "O" with bit 7 set brings ASCII back. Other bits:
//            stored and reported, no effect (MB4, position display while homing, is not modelled).
//  D del16   delay 0..65535 ms (busy meanwhile).
//  ? L       query: L is one of A P N R F S O B. Reply: L, '=', the value in decimal without leading
//            zeros, CR. A and P both report the position register (24-bit, 0..16777215), N the step
//            count, B the user-bit pin levels (bit 6 = 1 when ready; bit 1 = the input mux when
//            the read strobe is on). E.g. "? P\r" -> "P=1234\r".
//
// Timing: with no ramp, step k (1..N) of a move that starts at t0 happens at t0 + k/R (integer ns,
// rounded down) and the command ends with the last step: a move takes exactly N/R seconds.
//
// The position register is the chip's ONE register: it counts the steps of every channel. A driver
// multiplexing three axes keeps each axis's position itself and loads it with A before a P move.
// Relative moves wrap the register modulo 2^24.
//
// MMC-4S multiplexer (user bits)
// --------------------------------------------------------------------------------------------
//  bit 0  driver enable: 1 = every stepper driver powered (level, not latched). 0 = steps are lost.
//  bit 1  data: the value written to a general-purpose output; reads back the input mux (below).
//  bits 2-4  address A (0..7) for both muxes: (bits >> 2) & 7.
//  bit 5  read strobe: while 1, user bit 1 READS the input-mux port A (the chip's own bit 1 latch is
//         overridden for reading); while 0, bit 1 reads its latch.
//  bit 6  busy/CTS (chip output, 1 = ready).
//  bit 7  write strobe: on its RISING edge (0 -> 1) the output mux latches port A:
//           A = 0..3: motor channel A. Two readings (Mmc4sBoard's ChannelLatching), since the MMC-4S's
//                     manual is not at hand: PerLine (the default, the unkinder): channel A's line
//                     latches the data bit, 1 selects and 0 deselects it, several may be selected and
//                     each step pulse then steps every one; Address: channel A becomes THE selected
//                     channel, the data bit ignored. Channel 0 = X, 1 = Y, 2 = Z, 3 = unused (its steps
//                     go nowhere). A driver correct under both deselects the old channel (data 0 at
//                     its address) before it selects the new one (data 1).
//           A = 4..7: general-purpose output A takes the data bit (bit 1). Output 4 = spindle (1 = on).
//         A write-strobe level of 1 held while address bits change does not relatch. At power-up no
//         channel is selected and every general-purpose output is 0.
//  Input-mux ports: 0..2 = home switch of X, Y, Z (1 = switch CLOSED, i.e. axis below its home edge),
//  3 = channel 3 (reads 0), 4..7 = general-purpose inputs (0 unless a test sets them).
//
// The rig's mill (sim/mill): each axis's home switch is closed below machine coordinate 0 and open
// from 0 up; so `H 11H` (seek bit 1 = 0, switch open) with the input mux on that axis homes the axis
// onto machine coordinate 0 exactly, register = 0. Its last steps were +, so a following + move moves
// the axis at once and a - move first turns the axis's backlash (80/32/80 steps) without moving it.
// (`H 1` would seek the switch CLOSING while stepping +, which never happens from inside the
// workspace: it steps + until the far hard stop and, with no limit inputs wired, on and on.)
//
// Exact byte sequences (what the fake expects) for X = channel 0, Y = 1, Z = 2, drivers on:
//   select channel c:   "B <40H + 1 + 4c>\r" "B 7\r" "/B 7\r"   e.g. Y: "B 45H\r" "B 7\r" "/B 7\r"
//                       (bits 0-5 = enable, data 0, address c, read strobe off; then strobe up, down)
//   move n steps:       "N <n>\r" then "+\r" or "-\r" then "G\r"; busy n/R s.
//   home axis c:        select channel c as above, then "B <40H + 1 + 4c + 20H>\r" (read strobe on, so
//                       bit 1 reads c's home switch), then "H 11H\r"; afterwards "? P\r" -> "P=0\r".
//   query position:     "? P\r" -> "P=<decimal>\r"
//   spindle on / off:   "B 53H\r" (enable, data 1, address 4) "B 7\r" "/B 7\r"  /  "B 51H\r" "B 7\r" "/B 7\r"
// ============================================================================================

namespace stencil::sim::cy545 {

inline constexpr std::uint8_t kCarriageReturn = 0x0D;
inline constexpr int kReceiveBufferBytes = 3;
inline constexpr int kMaxLineCharacters = 32;
inline constexpr std::uint32_t kMax24Bit = 0xFFFFFF;
inline constexpr std::uint32_t kMaxRateStepsPerSecond = 27000;
inline constexpr std::uint32_t kDefaultRateStepsPerSecond = 1000;
inline constexpr std::uint32_t kDefaultMode = 0x80;      // ASCII commands, standard serial output
inline constexpr std::uint32_t kModeAsciiBit = 0x80;

// User bits.
inline constexpr int kBitDriverEnable = 0;
inline constexpr int kBitData = 1;
inline constexpr int kBitAddressLow = 2;  // bits 2-4
inline constexpr int kBitReadStrobe = 5;
inline constexpr int kBitBusyCts = 6;
inline constexpr int kBitWriteStrobe = 7;

inline constexpr int kMotorChannels = 4;   // output-mux ports 0-3
inline constexpr int kMuxPorts = 8;

}  // namespace stencil::sim::cy545
