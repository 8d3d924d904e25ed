// ByteWriter and ByteReader (journal_bytes.hpp): little-endian numbers and floats bit for bit, LEB128
// varints at their byte boundaries, zigzag small either side of zero, the extremes of every width,
// and a reader that gives zeros and says overrun rather than read past its span; the fixed-size
// encoders lay out the payloads journal_format.hpp gives. Against hand-written bytes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "firmware/services/journal/journal_bytes.hpp"
#include "firmware/services/journal/journal_format.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil::journal;

namespace {

std::vector<std::uint8_t> bytes_of(const ByteWriter& out) { return {out.data(), out.data() + out.size()}; }

std::vector<std::uint8_t> varint_bytes(std::uint64_t v) {
  ByteWriter out;
  out.varint(v);
  return bytes_of(out);
}

std::vector<std::uint8_t> zigzag_bytes(std::int64_t v) {
  ByteWriter out;
  out.zigzag(v);
  return bytes_of(out);
}

}  // namespace

TEST_GROUP(JournalBytes){};

TEST(JournalBytes, NumbersAreWrittenLowByteFirst) {
  ByteWriter out;
  out.u8(0xAB);
  out.u16(0x1234);
  out.u32(0xDEADBEEF);
  out.u64(0x0102030405060708ULL);
  out.i32(-2);
  out.i64(-1);
  const std::vector<std::uint8_t> want = {0xAB, 0x34, 0x12, 0xEF, 0xBE, 0xAD, 0xDE, 0x08, 0x07, 0x06,
                                          0x05, 0x04, 0x03, 0x02, 0x01, 0xFE, 0xFF, 0xFF, 0xFF, 0xFF,
                                          0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  CHECK(want == bytes_of(out));
  ByteReader in(out.data(), out.size());
  LONGS_EQUAL(0xAB, in.u8());
  LONGS_EQUAL(0x1234, in.u16());
  CHECK_EQUAL(0xDEADBEEFU, in.u32());
  CHECK_EQUAL(0x0102030405060708ULL, in.u64());
  LONGS_EQUAL(-2, in.i32());
  CHECK_EQUAL(std::int64_t{-1}, in.i64());
  LONGS_EQUAL(0, in.left());
  CHECK_FALSE(in.overrun());
  out.clear();
  LONGS_EQUAL(0, out.size());
}

// A replay must be exact: the bits of a float, NaN's payload and the sign of zero included.
TEST(JournalBytes, FloatsComeBackBitForBit) {
  const double doubles[] = {0.0, -0.0, 1.0 / 3.0, -1e-308, std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::denorm_min(), std::nan("0x5a5a")};
  const float floats[] = {-0.0F, 4.75F, std::numeric_limits<float>::max(), std::nanf("0x123")};
  ByteWriter out;
  for (const double v : doubles) {
    out.f64(v);
  }
  for (const float v : floats) {
    out.f32(v);
  }
  LONGS_EQUAL(7 * 8 + 4 * 4, out.size());
  // 1.0 / 3.0 is 0x3FD5555555555555: low byte first.
  CHECK_EQUAL(0x55, out.data()[16]);
  CHECK_EQUAL(0x3F, out.data()[23]);
  ByteReader in(out.data(), out.size());
  for (const double v : doubles) {
    const double back = in.f64();
    CHECK(std::memcmp(&v, &back, sizeof v) == 0);
  }
  for (const float v : floats) {
    const float back = in.f32();
    CHECK(std::memcmp(&v, &back, sizeof v) == 0);
  }
  CHECK_FALSE(in.overrun());
}

TEST(JournalBytes, AVarintTakesSevenBitsAByteLowFirstAndOneMoreByteAtEachBoundary) {
  CHECK((std::vector<std::uint8_t>{0x00}) == varint_bytes(0));
  CHECK((std::vector<std::uint8_t>{0x7F}) == varint_bytes(127));
  CHECK((std::vector<std::uint8_t>{0x80, 0x01}) == varint_bytes(128));
  CHECK((std::vector<std::uint8_t>{0xAC, 0x02}) == varint_bytes(300));
  CHECK((std::vector<std::uint8_t>{0xFF, 0x7F}) == varint_bytes(16383));
  CHECK((std::vector<std::uint8_t>{0x80, 0x80, 0x01}) == varint_bytes(16384));
  const std::vector<std::uint8_t> largest = varint_bytes(std::numeric_limits<std::uint64_t>::max());
  LONGS_EQUAL(10, largest.size());
  LONGS_EQUAL(0x01, largest.back());
  // Every width from 1 to 10 bytes reads back.
  for (unsigned bits = 0; bits <= 64; ++bits) {
    const std::uint64_t v = bits == 64 ? std::numeric_limits<std::uint64_t>::max() : (std::uint64_t{1} << bits) - 1;
    const std::vector<std::uint8_t> b = varint_bytes(v);
    LONGS_EQUAL(bits == 0 ? 1 : (bits + 6) / 7, b.size());
    ByteReader in(b.data(), b.size());
    CHECK_EQUAL(v, in.varint());
    LONGS_EQUAL(b.size(), in.at());
    CHECK_FALSE(in.overrun());
  }
}

TEST(JournalBytes, ZigzagKeepsSmallNumbersEitherSideOfZeroInOneByte) {
  CHECK((std::vector<std::uint8_t>{0}) == zigzag_bytes(0));
  CHECK((std::vector<std::uint8_t>{1}) == zigzag_bytes(-1));
  CHECK((std::vector<std::uint8_t>{2}) == zigzag_bytes(1));
  CHECK((std::vector<std::uint8_t>{3}) == zigzag_bytes(-2));
  CHECK((std::vector<std::uint8_t>{0x7F}) == zigzag_bytes(-64));
  CHECK((std::vector<std::uint8_t>{0x80, 0x01}) == zigzag_bytes(64));
  const std::int64_t values[] = {0, 1, -1, 63, -64, 64, -65, 1'000'000'007, -1'000'000'007,
                                 std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min()};
  for (const std::int64_t v : values) {
    const std::vector<std::uint8_t> b = zigzag_bytes(v);
    ByteReader in(b.data(), b.size());
    CHECK_EQUAL(v, in.zigzag());
    CHECK_FALSE(in.overrun());
  }
  LONGS_EQUAL(10, zigzag_bytes(std::numeric_limits<std::int64_t>::min()).size());
}

// No writer makes these: a varint cut short, one of eleven bytes, a tenth byte over 1 (bits past
// 64). Each is an overrun with a zero, not a number made up.
TEST(JournalBytes, AVarintCutShortTooLongOrPastSixtyFourBitsIsAnOverrunGivingZero) {
  const std::uint8_t cut[] = {0x80, 0x80};
  ByteReader short_in(cut, sizeof cut);
  CHECK_EQUAL(0U, short_in.varint());
  CHECK_TRUE(short_in.overrun());

  std::uint8_t eleven[11];
  std::memset(eleven, 0x80, sizeof eleven);
  eleven[10] = 0x00;
  ByteReader long_in(eleven, sizeof eleven);
  CHECK_EQUAL(0U, long_in.varint());
  CHECK_TRUE(long_in.overrun());

  std::uint8_t wide[10];
  std::memset(wide, 0xFF, sizeof wide);
  wide[9] = 0x02;  // bit 64
  ByteReader wide_in(wide, sizeof wide);
  CHECK_EQUAL(0U, wide_in.varint());
  CHECK_TRUE(wide_in.overrun());

  wide[9] = 0x01;  // bit 63: the largest there is
  ByteReader largest(wide, sizeof wide);
  CHECK_EQUAL(std::numeric_limits<std::uint64_t>::max(), largest.varint());
  CHECK_FALSE(largest.overrun());
}

TEST(JournalBytes, ReadingPastTheSpanGivesZerosAndSaysOverrunAndSkipStopsAtTheEnd) {
  const std::uint8_t three[] = {0x01, 0x02, 0x03};
  ByteReader in(three, sizeof three);
  LONGS_EQUAL(0x0201, in.u16());
  LONGS_EQUAL(1, in.left());
  CHECK(in.here() == three + 2);
  CHECK_FALSE(in.overrun());
  CHECK_EQUAL(0U, in.u32());  // 4 wanted, 1 left: none taken
  CHECK_TRUE(in.overrun());
  LONGS_EQUAL(0, in.left());
  LONGS_EQUAL(0, in.u8());

  ByteReader skipping(three, sizeof three);
  skipping.skip(3);
  CHECK_FALSE(skipping.overrun());
  LONGS_EQUAL(3, skipping.at());
  ByteReader over(three, sizeof three);
  over.skip(1);
  over.skip(3);
  CHECK_TRUE(over.overrun());
  LONGS_EQUAL(3, over.at());
}

// The fixed payloads are the sizes journal_format.hpp lays out, and their first field where it says.
TEST(JournalBytes, TheEncodersWriteThePayloadsTheFormatLaysOut) {
  stencil::control::JournalRecord record{};
  record.cycle = 0x1122334455667788ULL;
  record.status_bits = 0xBEEF;
  record.read_reason = stencil::hal::HapticFault::SampleNotFinite;
  ByteWriter cycle;
  encode_cycle(record, cycle);
  LONGS_EQUAL(kCyclePayloadBytes, cycle.size());
  LONGS_EQUAL(0x88, cycle.data()[0]);
  LONGS_EQUAL(0x11, cycle.data()[7]);
  // status_bits, read_status, read_reason close the payload.
  LONGS_EQUAL(0xEF, cycle.data()[kCyclePayloadBytes - 4]);
  LONGS_EQUAL(0xBE, cycle.data()[kCyclePayloadBytes - 3]);
  LONGS_EQUAL(static_cast<int>(stencil::hal::HapticFault::SampleNotFinite), cycle.data()[kCyclePayloadBytes - 1]);

  stencil::control::MachineCommandRecord target{7, -5, {-1, 2, 3}, {2, 0, 1}, {1.5, 2.5, 3.5}};
  ByteWriter machine;
  encode_machine_command(target, machine);
  LONGS_EQUAL(kMachineCommandPayloadBytes, machine.size());
  ByteReader in(machine.data(), machine.size());
  CHECK_EQUAL(7U, in.u64());
  CHECK_EQUAL(std::int64_t{-5}, in.i64());
  LONGS_EQUAL(-1, in.i32());
  LONGS_EQUAL(2, in.i32());
  LONGS_EQUAL(3, in.i32());
  LONGS_EQUAL(2, in.u8());
  LONGS_EQUAL(0, in.u8());
  LONGS_EQUAL(1, in.u8());
  DOUBLES_EQUAL(1.5, in.f64(), 0.0);

  stencil::control::CommandEvent event{3, 30, 2, stencil::control::CommandKind::Stop,
                                       stencil::control::CommandSource::Display, stencil::control::CommandOutcome::Done,
                                       0.25, 0.5};
  ByteWriter command;
  encode_command(event, command);
  LONGS_EQUAL(kCommandPayloadBytes, command.size());
  LONGS_EQUAL(static_cast<int>(stencil::control::CommandKind::Stop), command.data()[24]);  // the kind, as the reader checks it
  LONGS_EQUAL(static_cast<int>(stencil::control::CommandSource::Display), command.data()[25]);
}
