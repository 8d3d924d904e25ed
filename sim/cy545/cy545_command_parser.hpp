// Parsing one CY545 ASCII command line (without its CR) into a command, or the reason it is refused.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace stencil::sim::cy545 {

enum class ParseStatus : std::uint8_t {
  command,      // a supported, well-formed command
  empty,        // a bare CR: nothing to do
  malformed,    // ignored and counted
  unsupported,  // a real CY545 command the fake does not implement: ignored and counted
};

struct Cy545Command {
  char letter = 0;        // A..Z, '+', '-', '?'
  bool negated = false;   // a '/' prefix (B only)
  std::uint32_t argument = 0;  // the one numeric argument, when the command takes one
  char query_letter = 0;  // for '?': the queried command letter
};

struct ParseResult {
  ParseStatus status = ParseStatus::malformed;
  Cy545Command command{};
  const char* reason = "";   // what was wrong, for malformed and unsupported lines
  int column = 0;            // the character (0-based) where it went wrong
};

// Allocation-free; `line` excludes the terminating CR.
ParseResult parse_command_line(std::string_view line);

// One command in the binary format (mode register bit 7 clear): its letter and the `count` data
// bytes that followed the count byte, least significant first. The count must be the command's own
// size (0 for G I + -, 1 for a byte argument or the queried letter, 2 for D, 3 for A N P); anything
// else is malformed, as is a letter the chip has not.
ParseResult parse_binary_command(char letter, const std::uint8_t* data, std::size_t count);

// A number in the chip's syntax: decimal digits, or hex digits with an H suffix and a leading decimal
// digit. False when malformed or above 0xFFFFFFFF.
bool parse_number(std::string_view token, std::uint32_t& value);

}  // namespace stencil::sim::cy545
