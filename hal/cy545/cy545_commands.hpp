// The CY545's ASCII commands as bytes and its query replies parsed, with the MMC-4S user-bit codes
// the driver needs; pure functions, allocation-free (fuzzable, and safe anywhere).
//
// Framing (from the chip's manual, and sim/cy545/cy545_protocol.hpp which the fake implements):
// one letter, a space, the arguments, a carriage return; numbers in decimal, or in hex with an H
// suffix and a leading decimal digit (0ABH). A query "? L" is answered "L=<decimal>" CR.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace stencil::hal::cy545 {

// Positions and step counts are 24-bit on the chip.
inline constexpr std::uint32_t kMax24 = (1U << 24) - 1;

struct CommandBytes {
  std::array<char, 24> bytes;
  std::uint8_t size;
  [[nodiscard]] std::string_view view() const { return {bytes.data(), size}; }
};

// "G\r", "+\r", "-\r", "I\r": a letter alone. False (and size 0) for a letter the chip has not.
[[nodiscard]] bool bare_command(char letter, CommandBytes& out);
// "N 33\r", "R 1000\r", "D 5\r", "A 0\r": a letter and one decimal argument no larger than `max`.
[[nodiscard]] bool number_command(char letter, std::uint32_t argument, std::uint32_t max, CommandBytes& out);
// "B 45H\r": the user-bit command with its code in hex (0 to 0FFH).
[[nodiscard]] bool bit_command(std::uint8_t code, CommandBytes& out);
// "/B 7\r": clear user bit n (0 to 7).
[[nodiscard]] bool clear_bit_command(std::uint8_t bit, CommandBytes& out);
// "H 11H\r": seek home on a bit code (0-7 or 10H-17H).
[[nodiscard]] bool home_command(std::uint8_t code, CommandBytes& out);
// "? P\r": query register `letter`.
[[nodiscard]] bool query_command(char letter, CommandBytes& out);

// MMC-4S user bits (bit 0 driver enable, 1 data, 2-4 address, 5 read strobe, 6 busy/CTS (the
// chip's, never written), 7 write strobe). These codes write bits 0-5 at once (40H-7FH).
[[nodiscard]] constexpr std::uint8_t write_bits_code(bool drivers_on, bool data, std::uint8_t address,
                                                     bool read_strobe) {
  return static_cast<std::uint8_t>(0x40U | (drivers_on ? 0x01U : 0U) | (data ? 0x02U : 0U) |
                                   ((address & 0x07U) << 2U) | (read_strobe ? 0x20U : 0U));
}
inline constexpr std::uint8_t kWriteStrobeBit = 7;
// The mode register's power-up value (manual, chapter 9 "Operating Mode Command"): bit 7 set selects
// ASCII commands (clear: binary, which reads every later ASCII byte as a binary count or data), the
// low bits standard serial output for query replies. The driver sets it explicitly, since whatever
// ran before may have left another mode.
inline constexpr std::uint8_t kAsciiMode = 0x80;
// User bit 0 drives the MMC-4S's driver enable (bits 0-5 of "? B" read back the latches).
inline constexpr std::uint8_t kDriverEnableBit = 0x01;
// H 11H: seek until user bit 1 (the input mux's line while the read strobe is on) reads 0, i.e.
// the home switch of the selected input opens: the chip steps down into the switch, then up out.
inline constexpr std::uint8_t kHomeOnInputOpen = 0x11;

enum class ReplyStatus : std::uint8_t {
  Complete,    // value holds the number
  Incomplete,  // no carriage return yet: read more
  Garbled,     // byte `at` is not what a reply to this query has there
};

struct ReplyParse {
  ReplyStatus status;
  std::uint32_t value;
  std::size_t at;        // Garbled: the offending byte's index
  const char* expected;  // Garbled: what was expected there
  std::size_t length;    // Complete: bytes used, carriage return included
};

// The reply to "? <letter>": letter, '=', 1 to 8 decimal digits no larger than 24 bits, CR.
[[nodiscard]] ReplyParse parse_reply(std::string_view bytes, char letter);

}  // namespace stencil::hal::cy545
