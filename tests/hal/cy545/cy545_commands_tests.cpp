// The CY545 command bytes, exactly, and the query reply parser on good and bad bytes.
#include <string>
#include <string_view>

#include "hal/cy545/cy545_commands.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::hal::cy545;

namespace {

std::string bytes_of(const CommandBytes& command) { return std::string(command.view()); }

}  // namespace

TEST_GROUP(Cy545Commands){};

TEST(Cy545Commands, EveryCommandTheDriverSendsHasItsExactBytes) {
  CommandBytes c{};
  CHECK(bare_command('G', c));
  STRCMP_EQUAL("G\r", bytes_of(c).c_str());
  CHECK(bare_command('+', c));
  STRCMP_EQUAL("+\r", bytes_of(c).c_str());
  CHECK(bare_command('-', c));
  STRCMP_EQUAL("-\r", bytes_of(c).c_str());
  CHECK(bare_command('I', c));
  STRCMP_EQUAL("I\r", bytes_of(c).c_str());
  CHECK(number_command('N', 33, kMax24, c));
  STRCMP_EQUAL("N 33\r", bytes_of(c).c_str());
  CHECK(number_command('N', 0, kMax24, c));
  STRCMP_EQUAL("N 0\r", bytes_of(c).c_str());
  CHECK(number_command('N', kMax24, kMax24, c));
  STRCMP_EQUAL("N 16777215\r", bytes_of(c).c_str());
  CHECK(number_command('R', 1000, 27000, c));
  STRCMP_EQUAL("R 1000\r", bytes_of(c).c_str());
  CHECK(number_command('A', 0, kMax24, c));
  STRCMP_EQUAL("A 0\r", bytes_of(c).c_str());
  CHECK(bit_command(7, c));
  STRCMP_EQUAL("B 7H\r", bytes_of(c).c_str());
  CHECK(bit_command(0x45, c));
  STRCMP_EQUAL("B 45H\r", bytes_of(c).c_str());
  CHECK(bit_command(0xAB, c));
  STRCMP_EQUAL("B 0ABH\r", bytes_of(c).c_str());  // hex needs a leading decimal digit
  CHECK(bit_command(0x0C, c));
  STRCMP_EQUAL("B 0CH\r", bytes_of(c).c_str());
  CHECK(clear_bit_command(7, c));
  STRCMP_EQUAL("/B 7\r", bytes_of(c).c_str());
  CHECK(home_command(kHomeOnInputOpen, c));
  STRCMP_EQUAL("H 11H\r", bytes_of(c).c_str());
  CHECK(query_command('P', c));
  STRCMP_EQUAL("? P\r", bytes_of(c).c_str());
}

TEST(Cy545Commands, OutOfRangeArgumentsAndUnknownLettersMakeNoBytes) {
  CommandBytes c{};
  CHECK_FALSE(number_command('N', kMax24 + 1, kMax24, c));
  CHECK_EQUAL(0, c.size);
  CHECK_FALSE(number_command('R', 27001, 27000, c));
  CHECK_FALSE(number_command('Q', 1, 10, c));
  CHECK_FALSE(bare_command('X', c));
  CHECK_FALSE(clear_bit_command(8, c));
  CHECK_FALSE(home_command(0x08, c));
  CHECK_FALSE(home_command(0x18, c));
  CHECK_FALSE(query_command('Z', c));
}

TEST(Cy545Commands, TheMuxCodesSelectChannelsSpindleAndHomeInputs) {
  CHECK_EQUAL(0x41, write_bits_code(true, false, 0, false));  // X: drivers on, channel 0
  CHECK_EQUAL(0x45, write_bits_code(true, false, 1, false));  // Y
  CHECK_EQUAL(0x49, write_bits_code(true, false, 2, false));  // Z
  CHECK_EQUAL(0x53, write_bits_code(true, true, 4, false));   // spindle output 4 on
  CHECK_EQUAL(0x51, write_bits_code(true, false, 4, false));  // spindle off
  CHECK_EQUAL(0x61, write_bits_code(true, false, 0, true));   // X's home switch on the input line
  CHECK_EQUAL(0x69, write_bits_code(true, false, 2, true));
  CHECK_EQUAL(0x40, write_bits_code(false, false, 0, false)); // everything off: drivers limp
}

TEST(Cy545Commands, AQueryReplyIsTheLetterEqualsDigitsAndACarriageReturn) {
  ReplyParse r = parse_reply("P=1234\r", 'P');
  CHECK(r.status == ReplyStatus::Complete);
  CHECK_EQUAL(1234U, r.value);
  CHECK_EQUAL(7U, r.length);
  r = parse_reply("P=16777215\rjunk", 'P');
  CHECK(r.status == ReplyStatus::Complete);
  CHECK_EQUAL(kMax24, r.value);
  CHECK(parse_reply("", 'P').status == ReplyStatus::Incomplete);
  CHECK(parse_reply("P=12", 'P').status == ReplyStatus::Incomplete);
}

TEST(Cy545Commands, AGarbledReplyNamesTheByteAndWhatWasExpected) {
  ReplyParse r = parse_reply("X=12\r", 'P');
  CHECK(r.status == ReplyStatus::Garbled);
  CHECK_EQUAL(0U, r.at);
  r = parse_reply("P:12\r", 'P');
  CHECK(r.status == ReplyStatus::Garbled);
  CHECK_EQUAL(1U, r.at);
  STRCMP_EQUAL("'='", r.expected);
  r = parse_reply("P=1a\r", 'P');
  CHECK(r.status == ReplyStatus::Garbled);
  CHECK_EQUAL(3U, r.at);
  r = parse_reply("P=\r", 'P');
  CHECK(r.status == ReplyStatus::Garbled);
  CHECK_EQUAL(2U, r.at);
  CHECK(parse_reply("P=16777216\r", 'P').status == ReplyStatus::Garbled);  // beyond 24 bits
  CHECK(parse_reply("P=000000001\r", 'P').status == ReplyStatus::Garbled);  // too many digits
  CHECK(parse_reply("\r=083806", '\r').status == ReplyStatus::Garbled);  // not a register: found by the fuzzer
  const char high_bit[] = {static_cast<char>('P' | 0x80), '=', '1', '\r'};
  CHECK(parse_reply({high_bit, 4}, 'P').status == ReplyStatus::Garbled);
}
