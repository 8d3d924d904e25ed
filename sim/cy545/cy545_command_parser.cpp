// Parsing CY545 ASCII command lines: letters, arguments, decimal and H-suffixed hex numbers, ranges.
#include "sim/cy545/cy545_command_parser.hpp"

#include <cstddef>

#include "sim/cy545/cy545_protocol.hpp"

namespace stencil::sim::cy545 {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_hex_letter(char c) { return c >= 'A' && c <= 'F'; }
bool is_separator(char c) { return c == ' ' || c == ','; }

enum class Arity : std::uint8_t { none, number, query };

struct CommandSpec {
  char letter;
  Arity arity;
  std::uint32_t min;
  std::uint32_t max;
};

constexpr CommandSpec kSupported[] = {
    {'A', Arity::number, 0, kMax24Bit},
    {'B', Arity::number, 0, 0xFF},
    {'D', Arity::number, 0, 0xFFFF},
    {'F', Arity::number, 1, kMaxRateStepsPerSecond},
    {'G', Arity::none, 0, 0},
    {'H', Arity::number, 0, 0x17},
    {'I', Arity::none, 0, 0},
    {'N', Arity::number, 0, kMax24Bit},
    {'O', Arity::number, 0, 0xFF},
    {'P', Arity::number, 0, kMax24Bit},
    {'R', Arity::number, 1, kMaxRateStepsPerSecond},
    {'S', Arity::number, 0, 0xFF},
    {'W', Arity::number, 0, 0x17},
    {'+', Arity::none, 0, 0},
    {'-', Arity::none, 0, 0},
    {'?', Arity::query, 0, 0},
};

constexpr std::string_view kUnsupported = "CEJLQTUVXYZ0[\"";
constexpr std::string_view kQueryable = "APNRFSOB";

const CommandSpec* find_spec(char letter) {
  for (const CommandSpec& spec : kSupported) {
    if (spec.letter == letter) return &spec;
  }
  return nullptr;
}

ParseResult refuse(ParseStatus status, const char* reason, std::size_t column) {
  ParseResult result;
  result.status = status;
  result.reason = reason;
  result.column = static_cast<int>(column);
  return result;
}

// H and W take one user bit and the level to match: 0-7 (high) or 10H-17H (low).
bool is_bit_level(std::uint32_t value) { return value <= 0x07 || (value >= 0x10 && value <= 0x17); }

}  // namespace

bool parse_number(std::string_view token, std::uint32_t& value) {
  if (token.empty() || !is_digit(token.front())) return false;
  const bool hex = token.back() == 'H';
  const std::string_view digits = hex ? token.substr(0, token.size() - 1) : token;
  if (digits.empty()) return false;
  const std::uint64_t base = hex ? 16 : 10;
  std::uint64_t accumulated = 0;
  for (const char c : digits) {
    std::uint64_t digit = 0;
    if (is_digit(c)) {
      digit = static_cast<std::uint64_t>(c - '0');
    } else if (hex && is_hex_letter(c)) {
      digit = static_cast<std::uint64_t>(c - 'A' + 10);
    } else {
      return false;
    }
    accumulated = accumulated * base + digit;
    if (accumulated > 0xFFFFFFFFull) return false;
  }
  value = static_cast<std::uint32_t>(accumulated);
  return true;
}

ParseResult parse_binary_command(char letter, const std::uint8_t* data, std::size_t count) {
  const CommandSpec* spec = find_spec(letter);
  if (spec == nullptr) {
    return refuse(kUnsupported.find(letter) != std::string_view::npos ? ParseStatus::unsupported : ParseStatus::malformed,
                  "binary mode: not a command letter", 0);
  }
  std::size_t size = 0;
  if (spec->arity == Arity::query) {
    size = 1;
  } else if (spec->arity == Arity::number) {
    // The chip's own sizes (manual, chapter 4): pos24/num24 three bytes, del16 two, the rest one
    // (R and F included: on the chip they are one byte, whatever the fake's ASCII R accepts).
    size = spec->max > 0xFFFF ? 3 : letter == 'D' ? 2 : 1;
  }
  if (count != size) return refuse(ParseStatus::malformed, "binary mode: the data count is not this command's size", 1);
  ParseResult result;
  result.status = ParseStatus::command;
  result.command.letter = letter;
  if (spec->arity == Arity::query) {
    if (kQueryable.find(static_cast<char>(data[0])) == std::string_view::npos) {
      return refuse(ParseStatus::malformed, "binary mode: expected one of A P N R F S O B after '?'", 2);
    }
    result.command.query_letter = static_cast<char>(data[0]);
    return result;
  }
  std::uint32_t value = 0;
  for (std::size_t i = count; i > 0; --i) value = (value << 8U) | data[i - 1];
  if (spec->arity == Arity::number && (value < spec->min || value > spec->max)) {
    return refuse(ParseStatus::malformed, "binary mode: argument out of range", 2);
  }
  if ((letter == 'H' || letter == 'W') && !is_bit_level(value)) {
    return refuse(ParseStatus::malformed, "binary mode: expected a bit 0-7 or 10H-17H", 2);
  }
  result.command.argument = value;
  return result;
}

ParseResult parse_command_line(std::string_view line) {
  if (line.empty()) {
    ParseResult result;
    result.status = ParseStatus::empty;
    return result;
  }
  if (line.size() > static_cast<std::size_t>(kMaxLineCharacters)) {
    return refuse(ParseStatus::malformed, "line longer than 32 characters", static_cast<std::size_t>(kMaxLineCharacters));
  }
  std::size_t at = 0;
  bool negated = false;
  if (line[at] == '/') {
    negated = true;
    ++at;
    if (at >= line.size() || line[at] != 'B') {
      return refuse(ParseStatus::malformed, "expected B after the '/' prefix", at);
    }
  }
  const char letter = line[at];
  const CommandSpec* spec = find_spec(letter);
  if (spec == nullptr) {
    if (kUnsupported.find(letter) != std::string_view::npos) {
      return refuse(ParseStatus::unsupported, "a CY545 command the fake does not implement", at);
    }
    return refuse(ParseStatus::malformed, "expected an upper-case command letter, '+', '-', '?' or '/B'", at);
  }
  ++at;
  // Tolerate trailing spaces after the letter and after the last argument.
  std::size_t end = line.size();
  while (end > at && line[end - 1] == ' ') --end;

  ParseResult result;
  result.status = ParseStatus::command;
  result.command.letter = letter;
  result.command.negated = negated;

  if (at == end) {
    if (spec->arity != Arity::none) return refuse(ParseStatus::malformed, "missing argument", at);
    return result;
  }
  if (line[at] != ' ') return refuse(ParseStatus::malformed, "expected a space after the command letter", at);
  if (spec->arity == Arity::none) return refuse(ParseStatus::malformed, "this command takes no argument", at);
  while (at < end && is_separator(line[at])) ++at;
  std::size_t token_end = at;
  while (token_end < end && !is_separator(line[token_end])) ++token_end;
  const std::string_view token = line.substr(at, token_end - at);
  std::size_t rest = token_end;
  while (rest < end && is_separator(line[rest])) ++rest;
  if (rest != end) return refuse(ParseStatus::malformed, "too many arguments", rest);

  if (spec->arity == Arity::query) {
    if (token.size() != 1 || kQueryable.find(token.front()) == std::string_view::npos) {
      return refuse(ParseStatus::malformed, "expected one of A P N R F S O B after '?'", at);
    }
    result.command.query_letter = token.front();
    return result;
  }
  std::uint32_t value = 0;
  if (!parse_number(token, value)) {
    return refuse(ParseStatus::malformed, "expected a decimal number or hex digits with an H suffix and a leading digit",
                  at);
  }
  if (negated) value ^= 0x10;  // the manual: '/' XORs the bit argument with 10H
  if (value < spec->min || value > spec->max) return refuse(ParseStatus::malformed, "argument out of range", at);
  if ((letter == 'H' || letter == 'W') && !is_bit_level(value)) {
    return refuse(ParseStatus::malformed, "expected a bit 0-7 (match 1) or 10H-17H (match 0)", at);
  }
  result.command.argument = value;
  return result;
}

}  // namespace stencil::sim::cy545
