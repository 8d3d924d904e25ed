// The CY545 line parser: decimal and hex numbers, 24-bit limits, argument counts, refused lines.
#include <cstring>
#include <string_view>

#include "sim/cy545/cy545_command_parser.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim::cy545;

namespace {

std::uint32_t number(std::string_view token) {
  std::uint32_t value = 0xDEADBEEF;
  CHECK_TRUE(parse_number(token, value));
  return value;
}

void check_malformed(std::string_view line, const char* reason_part) {
  const ParseResult result = parse_command_line(line);
  CHECK_TRUE_TEXT(result.status == ParseStatus::malformed, std::string(line).c_str());
  CHECK_TRUE_TEXT(std::strstr(result.reason, reason_part) != nullptr, result.reason);
}

}  // namespace

TEST_GROUP(Cy545CommandParser){};

TEST(Cy545CommandParser, DecimalAndHexWithLeadingDigitAndHSuffix) {
  UNSIGNED_LONGS_EQUAL(135, number("135"));
  UNSIGNED_LONGS_EQUAL(135, number("87H"));
  UNSIGNED_LONGS_EQUAL(0xAB, number("0ABH"));
  UNSIGNED_LONGS_EQUAL(0, number("0"));
  UNSIGNED_LONGS_EQUAL(0xFFFFFF, number("0FFFFFFH"));
  UNSIGNED_LONGS_EQUAL(16777215, number("16777215"));
  std::uint32_t value = 0;
  CHECK_FALSE(parse_number("ABH", value));    // no leading digit
  CHECK_FALSE(parse_number("0AB", value));    // hex digits without H
  CHECK_FALSE(parse_number("0abh", value));   // lower case
  CHECK_FALSE(parse_number("H", value));
  CHECK_FALSE(parse_number("", value));
  CHECK_FALSE(parse_number("4294967296", value));
  CHECK_FALSE(parse_number("1 2", value));
}

TEST(Cy545CommandParser, CommandsWithAndWithoutArguments) {
  ParseResult result = parse_command_line("N 1000");
  CHECK_TRUE(result.status == ParseStatus::command);
  LONGS_EQUAL('N', result.command.letter);
  UNSIGNED_LONGS_EQUAL(1000, result.command.argument);
  result = parse_command_line("G");
  CHECK_TRUE(result.status == ParseStatus::command);
  LONGS_EQUAL('G', result.command.letter);
  result = parse_command_line("+");
  LONGS_EQUAL('+', result.command.letter);
  result = parse_command_line("? P");
  CHECK_TRUE(result.status == ParseStatus::command);
  LONGS_EQUAL('P', result.command.query_letter);
  result = parse_command_line("R 87H  ");  // trailing spaces tolerated
  CHECK_TRUE(result.status == ParseStatus::command);
  UNSIGNED_LONGS_EQUAL(135, result.command.argument);
  CHECK_TRUE(parse_command_line("").status == ParseStatus::empty);
}

TEST(Cy545CommandParser, SlashBXorsTheBitArgumentWith10H) {
  ParseResult result = parse_command_line("/B 2");
  CHECK_TRUE(result.status == ParseStatus::command);
  CHECK_TRUE(result.command.negated);
  UNSIGNED_LONGS_EQUAL(0x12, result.command.argument);
  result = parse_command_line("/B 12H");
  UNSIGNED_LONGS_EQUAL(0x02, result.command.argument);
  check_malformed("/N 2", "B after the '/'");
}

TEST(Cy545CommandParser, TwentyFourBitLimits) {
  CHECK_TRUE(parse_command_line("N 16777215").status == ParseStatus::command);
  CHECK_TRUE(parse_command_line("P 0FFFFFFH").status == ParseStatus::command);
  CHECK_TRUE(parse_command_line("A 16777215").status == ParseStatus::command);
  check_malformed("N 16777216", "out of range");
  check_malformed("P 1000000H", "out of range");
  check_malformed("A 99999999", "out of range");
}

TEST(Cy545CommandParser, RatesSlopeBitsAndDelayRanges) {
  check_malformed("R 0", "out of range");
  check_malformed("R 27001", "out of range");
  CHECK_TRUE(parse_command_line("R 27000").status == ParseStatus::command);
  check_malformed("F 0", "out of range");
  check_malformed("S 256", "out of range");
  check_malformed("B 256", "out of range");
  check_malformed("O 100H", "out of range");
  check_malformed("D 65536", "out of range");
  check_malformed("H 8", "bit 0-7");
  check_malformed("W 20H", "out of range");
  CHECK_TRUE(parse_command_line("H 11H").status == ParseStatus::command);
  CHECK_TRUE(parse_command_line("W 7").status == ParseStatus::command);
}

TEST(Cy545CommandParser, MalformedLinesNameTheProblemAndColumn) {
  check_malformed("n 5", "upper-case");
  check_malformed("N5", "space after the command letter");
  check_malformed("N", "missing argument");
  check_malformed("G 5", "takes no argument");
  check_malformed("N 5 6", "too many arguments");
  check_malformed("N 5,6", "too many arguments");
  check_malformed("N x", "decimal number");
  check_malformed("?", "missing argument");
  check_malformed("? Q", "one of A P N R F S O B");
  check_malformed("? PP", "one of A P N R F S O B");
  check_malformed("\nN 5", "upper-case");
  check_malformed("M", "upper-case");
  check_malformed("N 123456789012345678901234567890123", "longer than 32");
  const ParseResult result = parse_command_line("N 12Z");
  LONGS_EQUAL(2, result.column);
}

TEST(Cy545CommandParser, RealCommandsTheFakeDoesNotImplementAreUnsupported) {
  for (const char* line : {"C", "E", "J 5", "L 2,3", "Q", "T 1,2", "X", "Y 100", "Z 1,2", "0"}) {
    CHECK_TRUE_TEXT(parse_command_line(line).status == ParseStatus::unsupported, line);
  }
}
