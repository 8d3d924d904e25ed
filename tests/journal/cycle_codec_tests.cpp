// The compact cycle: every field comes back bit for bit whatever it holds, the tool whole exactly
// where the resume and the replay need it, a moving hand in about nine bytes, and bytes that make no
// sense refused with what was expected.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "firmware/services/journal/cycle_codec.hpp"
#include "firmware/services/journal/journal_bytes.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::JournalRecord;
using stencil::control::SafeReason;
using namespace stencil::journal;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A hand moving at about 40 mm/s, its position in whole micrometres as the wires give it; the
// virtual tool following; the touched set growing now and then.
JournalRecord moving(std::uint64_t cycle) {
  JournalRecord r{};
  const double t = static_cast<double>(cycle) * 1e-3;
  r.cycle = cycle;
  r.time_ns = 1'000'000'017 + static_cast<std::int64_t>(cycle) * 1'000'000;
  r.device_mm[0] = std::round((12.0 + 40.0 * t) * 1e3) * 1e-3;
  r.device_mm[1] = std::round((30.0 * std::sin(t)) * 1e3) * 1e-3;
  r.device_mm[2] = std::round(-4.0 * 1e3) * 1e-3;
  r.angles_rad[0] = 0.0;
  r.angles_rad[1] = 0.0;
  r.sample_counter = static_cast<std::uint32_t>(cycle + 5);
  r.fresh = true;
  r.virtual_tip_mm[0] = 0.5 * r.device_mm[0] + 1e-9 * t;
  r.virtual_tip_mm[1] = 0.5 * r.device_mm[1];
  r.virtual_tip_mm[2] = 3.0 + std::cos(t);
  r.touched_triangles = static_cast<std::uint32_t>(cycle / 40);
  r.force_n[0] = static_cast<float>(std::sin(t));
  r.max_force_n = 1.5;
  r.max_offset_mm = 0.25;
  return r;
}

void check_same(const JournalRecord& want, const RecordedCycle& got) {
  const JournalRecord& r = got.record;
  LONGS_EQUAL(want.cycle, r.cycle);
  LONGS_EQUAL(want.time_ns, r.time_ns);
  for (int i = 0; i < 3; ++i) {
    CHECK(same_bits(want.device_mm[i], r.device_mm[i]));
  }
  CHECK(same_bits(want.angles_rad[0], r.angles_rad[0]) && same_bits(want.angles_rad[1], r.angles_rad[1]));
  LONGS_EQUAL(want.sample_counter, r.sample_counter);
  CHECK_EQUAL(want.fresh, r.fresh);
  LONGS_EQUAL(tip_check(want.virtual_tip_mm), got.tip_check);
  if (got.tool_recorded) {
    for (int i = 0; i < 3; ++i) {
      CHECK(same_bits(want.virtual_tip_mm[i], r.virtual_tip_mm[i]));
      CHECK(want.force_n[i] == r.force_n[i]);
    }
  } else {
    CHECK(std::isnan(r.virtual_tip_mm[0]) && std::isnan(r.force_n[2]));  // unknown, never a guess
  }
  LONGS_EQUAL(want.touched_triangles, r.touched_triangles);
  CHECK(want.safe_reason == r.safe_reason);
  LONGS_EQUAL(want.status_bits, r.status_bits);
  CHECK(want.read_status == r.read_status && want.read_reason == r.read_reason);
  CHECK_TRUE(got.maxima_recorded);
  CHECK(same_bits(want.max_force_n, r.max_force_n) && same_bits(want.max_offset_mm, r.max_offset_mm));
}

std::vector<RecordedCycle> decode_all(const ByteWriter& bytes, std::size_t count) {
  CycleDecoder decoder;
  ByteReader in(bytes.data(), bytes.size());
  std::vector<RecordedCycle> out(count);
  for (RecordedCycle& cycle : out) {
    std::string error;
    CHECK_TEXT(decoder.decode(in, cycle, error), error.c_str());
  }
  LONGS_EQUAL(0, in.left());
  return out;
}

std::string decode_error(const std::vector<std::uint8_t>& bytes, bool after_key) {
  CycleDecoder decoder;
  ByteWriter key;
  CycleEncoder encoder;
  encoder.encode(moving(0), key);
  RecordedCycle cycle;
  std::string error;
  if (after_key) {
    ByteReader first(key.data(), key.size());
    CHECK_TRUE(decoder.decode(first, cycle, error));
  }
  ByteReader in(bytes.data(), bytes.size());
  CHECK_FALSE(decoder.decode(in, cycle, error));
  return error;
}

}  // namespace

TEST_GROUP(CycleCodec){};

TEST(CycleCodec, AMovingHandComesBackBitForBitInAboutNineBytesACycle) {
  constexpr std::size_t kCycles = 3000;
  CycleEncoder encoder;
  ByteWriter bytes;
  for (std::uint64_t c = 0; c < kCycles; ++c) {
    encoder.encode(moving(c), bytes);
  }
  const std::vector<RecordedCycle> got = decode_all(bytes, kCycles);
  for (std::uint64_t c = 0; c < kCycles; ++c) {
    check_same(moving(c), got[c]);
    // Whole at a key (the first, then every thousandth) and wherever the touched set grew.
    CHECK_EQUAL(c % CycleEncoder::kKeyEvery == 0 || c % 40 == 0, got[c].tool_recorded);
  }
  // 115 bytes a cycle in version 4; the keys and the tools recorded included.
  const double per_cycle = static_cast<double>(bytes.size()) / kCycles;
  CHECK_TEXT(per_cycle < 10.0, std::to_string(per_cycle).c_str());
}

TEST(CycleCodec, EveryFieldThatChangesComesBackWhateverItHolds) {
  std::vector<JournalRecord> records;
  for (std::uint64_t c = 0; c < 60; ++c) {
    records.push_back(moving(c));
  }
  records[3].device_mm[1] = 0.1 + 0.2;  // no whole number of micrometres: as it is
  records[4].device_mm[1] = -0.0;       // the same steps as +0 but not the same bits
  records[5].device_mm[2] = std::numeric_limits<double>::quiet_NaN();
  records[6].device_mm[2] = std::numeric_limits<double>::infinity();
  records[7].angles_rad[0] = 0.123456;   // whole microradians
  records[8].angles_rad[1] = 1e-4 * 3;   // a CAN angle: not a whole microradian's bits
  records[9].sample_counter = records[8].sample_counter;  // stale: the counter stays
  records[9].fresh = false;
  records[10].time_ns += 250'000;        // a late cycle
  records[12].cycle += 5;                // cycles the record skipped
  for (std::size_t i = 13; i < records.size(); ++i) {
    records[i].cycle += 5;
  }
  records[14].safe_reason = SafeReason::DeviceStale;
  records[15].status_bits = 0x8001;
  records[16].read_status = stencil::hal::ReadStatus::Rejected;
  records[16].read_reason = stencil::hal::HapticFault::SampleOutOfRange;
  records[17].max_force_n = 5.0;
  records[17].touched_triangles = 3;  // grew
  records[18].touched_triangles = 0;  // fewer: a key
  records[19].sample_counter = 0xFFFFFFFFU;
  records[20].sample_counter = 0;  // wraps
  records[21].time_ns -= 3'000'000'000;  // time that ran backwards is still recorded as it was
  CycleEncoder encoder;
  ByteWriter bytes;
  for (const JournalRecord& r : records) {
    encoder.encode(r, bytes);
  }
  const std::vector<RecordedCycle> got = decode_all(bytes, records.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    check_same(records[i], got[i]);
  }
  CHECK_TRUE(got[14].tool_recorded);  // the safe state came: the tool where it stopped
  CHECK_TRUE(got[17].tool_recorded);  // grew
  CHECK_TRUE(got[18].tool_recorded);  // the key
  CHECK_FALSE(got[19].tool_recorded);
}

TEST(CycleCodec, ARunsFirstCycleIsAKeyAndADecoderWithoutOneRefusesTheRest) {
  CycleEncoder encoder;
  ByteWriter first;
  encoder.encode(moving(0), first);
  ByteWriter second;
  encoder.encode(moving(1), second);
  CHECK_EQUAL(1, first.data()[0] & 1);
  CHECK_EQUAL(0, second.data()[0] & 1);
  STRCMP_EQUAL("a cycle with no key cycle before it in its run (a run's first cycle is a key)",
               decode_error({second.data(), second.data() + second.size()}, false).c_str());
  encoder.restart();  // a resumed run
  ByteWriter again;
  encoder.encode(moving(2), again);
  CHECK_EQUAL(1, again.data()[0] & 1);
}

TEST(CycleCodec, BytesThatMakeNoSenseAreRefusedSayingWhatWasExpected) {
  STRCMP_CONTAINS("a key cycle's flags 5", decode_error({1 | 4}, false).c_str());
  STRCMP_CONTAINS("a key cycle cut short", decode_error({1, 0, 0}, false).c_str());
  STRCMP_CONTAINS("second flags byte 64", decode_error({128, 64}, true).c_str());
  STRCMP_CONTAINS("device masks 128", decode_error({16, 128}, true).c_str());
  STRCMP_CONTAINS("device masks 64 and 16", decode_error({16, 64, 16}, true).c_str());
  STRCMP_CONTAINS("touched set growing by 0", decode_error({64, 1, 2, 3, 4, 0}, true).c_str());
  STRCMP_CONTAINS("safe reason 200", decode_error({128, 1, 1, 2, 3, 4, 200}, true).c_str());
  // A number longer than ten bytes.
  STRCMP_CONTAINS("cut short (or a number in it longer than 10 bytes)",
                  decode_error({4, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 1}, true).c_str());
  // Every cut of a cycle with every field in it is refused, never misread.
  CycleEncoder encoder;
  ByteWriter key;
  JournalRecord r = moving(0);
  encoder.encode(r, key);
  JournalRecord next = moving(1);
  next.cycle += 3;
  next.time_ns += 7;
  next.sample_counter += 9;
  next.device_mm[0] = 0.1 + 0.2;
  next.angles_rad[0] = 0.5;
  next.touched_triangles += 2;
  next.safe_reason = SafeReason::Stopped;
  next.status_bits = 3;
  next.read_status = stencil::hal::ReadStatus::Stale;
  next.max_offset_mm = 9.0;
  ByteWriter full;
  encoder.encode(next, full);
  for (std::size_t cut = 1; cut < full.size(); ++cut) {
    STRCMP_CONTAINS("cut short", decode_error({full.data(), full.data() + full.size() - cut}, true).c_str());
  }
}
