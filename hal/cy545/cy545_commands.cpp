// CY545 command bytes and reply parsing.
#include "hal/cy545/cy545_commands.hpp"

namespace stencil::hal::cy545 {
namespace {

constexpr std::string_view kBareLetters = "GI+-";
constexpr std::string_view kNumberLetters = "NAPRFSODW";

void put(CommandBytes& out, char c) { out.bytes[out.size++] = c; }

void put_decimal(CommandBytes& out, std::uint32_t value) {
  char digits[10];
  std::size_t count = 0;
  do {
    digits[count++] = static_cast<char>('0' + value % 10U);
    value /= 10U;
  } while (value > 0U);
  while (count > 0) {
    put(out, digits[--count]);
  }
}

// Hex with a leading decimal digit and the H suffix: 7 -> "7H", 0x45 -> "45H", 0xAB -> "0ABH".
void put_hex(CommandBytes& out, std::uint8_t value) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  const char high = kDigits[value >> 4U];
  const char low = kDigits[value & 0x0FU];
  if (value >= 0x10U) {
    if (high > '9') {
      put(out, '0');
    }
    put(out, high);
  } else if (low > '9') {
    put(out, '0');
  }
  put(out, low);
  put(out, 'H');
}

}  // namespace

bool bare_command(char letter, CommandBytes& out) {
  out.size = 0;
  if (kBareLetters.find(letter) == std::string_view::npos) {
    return false;
  }
  put(out, letter);
  put(out, '\r');
  return true;
}

bool number_command(char letter, std::uint32_t argument, std::uint32_t max, CommandBytes& out) {
  out.size = 0;
  if (kNumberLetters.find(letter) == std::string_view::npos || argument > max || max > kMax24) {
    return false;
  }
  put(out, letter);
  put(out, ' ');
  put_decimal(out, argument);
  put(out, '\r');
  return true;
}

bool bit_command(std::uint8_t code, CommandBytes& out) {
  out.size = 0;
  put(out, 'B');
  put(out, ' ');
  put_hex(out, code);
  put(out, '\r');
  return true;
}

bool clear_bit_command(std::uint8_t bit, CommandBytes& out) {
  out.size = 0;
  if (bit > 7U) {
    return false;
  }
  put(out, '/');
  put(out, 'B');
  put(out, ' ');
  put_decimal(out, bit);
  put(out, '\r');
  return true;
}

bool home_command(std::uint8_t code, CommandBytes& out) {
  out.size = 0;
  if (!(code <= 0x07U || (code >= 0x10U && code <= 0x17U))) {
    return false;
  }
  put(out, 'H');
  put(out, ' ');
  put_hex(out, code);
  put(out, '\r');
  return true;
}

bool query_command(char letter, CommandBytes& out) {
  out.size = 0;
  if (std::string_view("APNRFSOB").find(letter) == std::string_view::npos) {
    return false;
  }
  put(out, '?');
  put(out, ' ');
  put(out, letter);
  put(out, '\r');
  return true;
}

ReplyParse parse_reply(std::string_view bytes, char letter) {
  ReplyParse result{ReplyStatus::Incomplete, 0, 0, "", 0};
  const auto garbled = [&](std::size_t at, const char* expected) {
    result.status = ReplyStatus::Garbled;
    result.at = at;
    result.expected = expected;
    return result;
  };
  if (std::string_view("APNRFSOB").find(letter) == std::string_view::npos) {
    return garbled(0, "a reply to a query of a register the chip has");  // the caller's mistake, refused
  }
  if (bytes.empty()) {
    return result;
  }
  if (bytes[0] != letter) {
    return garbled(0, "the queried register's letter");
  }
  if (bytes.size() < 2) {
    return result;
  }
  if (bytes[1] != '=') {
    return garbled(1, "'='");
  }
  std::uint64_t value = 0;
  std::size_t digits = 0;
  for (std::size_t i = 2; i < bytes.size(); ++i) {
    const char c = bytes[i];
    if (c == '\r') {
      if (digits == 0) {
        return garbled(i, "a decimal digit");
      }
      result.status = ReplyStatus::Complete;
      result.value = static_cast<std::uint32_t>(value);
      result.length = i + 1;
      return result;
    }
    if (c < '0' || c > '9') {
      return garbled(i, "a decimal digit or a carriage return");
    }
    if (++digits > 8) {
      return garbled(i, "at most 8 digits");
    }
    value = value * 10U + static_cast<std::uint64_t>(c - '0');
    if (value > kMax24) {
      return garbled(i, "a value within 24 bits");
    }
  }
  return result;
}

}  // namespace stencil::hal::cy545
