// The journal reader: a torn tail at any byte is found and ignored, never misread; damage that is
// not a crash's (a flipped bit with records after it, a record where its version has none, a value
// out of range) is an error naming the offset; not a journal, another version, a file that is not
// one are errors naming what was expected; version 2 journals still read. The bytes are the real
// writer's (or OldJournal's), damaged here on purpose.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <zlib.h>

#include "firmware/services/journal/cycle_codec.hpp"
#include "firmware/services/journal/journal_bytes.hpp"
#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/journal_fixtures.hpp"
#include "tests/support/old_journal.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::JournalRecord;
using stencil::control::SafeReason;
using stencil::testing::OldJournal;
using namespace stencil::journal;
using namespace stencil::testing;

TEST_GROUP(JournalReader){};

// A crash can cut the file anywhere: every cut inside the last record (cycles 100-149) reads every
// record before it and reports the rest as the tail; none is misread.
TEST(JournalReader, ATornTailAtAnyByteIsIgnoredAndEverythingBeforeItReads) {
  TempJournal file;
  write_job(file.path, 150);
  const std::vector<std::uint8_t> whole = file.bytes();
  const std::vector<std::size_t> starts = record_starts(whole);
  LONGS_EQUAL(4, starts.size());  // start, two Cycles records, the end of the file
  const std::size_t last = whole.size() - starts[2];
  for (std::size_t cut = 1; cut < last; ++cut) {
    Seen seen;
    const JournalReadResult read = read_journal(whole.data(), whole.size() - cut, seen.visitor());
    CHECK_TRUE(read.ok);
    LONGS_EQUAL(100, seen.cycles.size());
    LONGS_EQUAL(last - cut, read.tail_bytes);
    CHECK_FALSE(read.tail.empty());
    check_same(record_of(99), seen.cycles.back());
  }
}

TEST(JournalReader, AFlippedBitWithRecordsAfterItIsDamageThatSaysWhereAndInTheLastRecordATornTail) {
  TempJournal file;
  write_job(file.path, 350);  // cycles 0-99, 100-199, 200-299, 300-349
  const std::vector<std::uint8_t> whole = file.bytes();
  const std::vector<std::size_t> starts = record_starts(whole);
  LONGS_EQUAL(6, starts.size());
  const std::size_t second = starts[2];
  std::vector<std::uint8_t> bytes = whole;
  bytes[second + 20] ^= 0x10;  // inside the second Cycles record's payload
  Seen seen;
  JournalReadResult read = read_journal(bytes.data(), bytes.size(), seen.visitor());
  CHECK_FALSE(read.ok);
  LONGS_EQUAL(100, seen.cycles.size());  // what came before it was read
  LONGS_EQUAL(second, read.good_bytes);
  STRCMP_CONTAINS(("journal offset " + std::to_string(second) + ": a record whose CRC-32 does not match, with " +
                   std::to_string(whole.size() - starts[3]) + " bytes after it")
                      .c_str(),
                  read.error.c_str());
  const std::size_t last = starts[4];
  bytes = whole;
  bytes[last + 20] ^= 0x10;  // the last record: a torn write
  Seen seen_last;
  read = read_journal(bytes.data(), bytes.size(), seen_last.visitor());
  CHECK_TRUE(read.ok);
  LONGS_EQUAL(300, seen_last.cycles.size());
  LONGS_EQUAL(whole.size() - last, read.tail_bytes);
  STRCMP_CONTAINS("a last record whose CRC-32 does not match", read.tail.c_str());
}

TEST(JournalReader, NotAJournalOrAnotherVersionIsAnErrorNamingWhatWasExpected) {
  const std::uint8_t text[] = "t_s,x_mm,y_mm,z_mm\n";
  Seen seen;
  JournalReadResult read = read_journal(text, sizeof text, seen.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("not a journal (expected the magic STENCILJ", read.error.c_str());
  TempJournal file;
  write_job(file.path, 1);
  std::vector<std::uint8_t> bytes = file.bytes();
  bytes[8] = 9;
  read = read_journal(bytes.data(), bytes.size(), seen.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("journal offset 8: version 9; this program reads versions 2 to 5", read.error.c_str());
  read = read_journal_file("/nonexistent/journal", seen.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_EQUAL("/nonexistent/journal: cannot be read", read.error.c_str());
  read = read_journal_file("/dev/zero", seen.visitor());  // endless: refused before reading
  CHECK_FALSE(read.ok);
  STRCMP_EQUAL("/dev/zero: not a regular file (a journal is one)", read.error.c_str());
}

TEST(JournalReader, AMachineCommandThatNamesNoAxisOrAnInfiniteTargetIsAnErrorNamingTheOffset) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  auto bad = command_of(1);
  bad.order[1] = 7;
  CHECK_TRUE(writer.append_machine_command(bad));
  CHECK_TRUE(writer.append_machine_command(command_of(2)));
  CHECK_TRUE(writer.close());
  Seen seen;
  const JournalReadResult read = read_journal_file(file.path, seen.visitor());
  CHECK_FALSE(read.ok);
  CHECK(read.error.find("journal offset ") != std::string::npos);
  CHECK(read.error.find("leg order") != std::string::npos);
  LONGS_EQUAL(0, seen.commands.size());
}

// As version 2 wrote it: a Cycle record per cycle, a safe-state record without its source (read as
// the cycle's own).
TEST(JournalReader, AVersion2JournalStillReads) {
  OldJournal version2(2);
  for (int i = 0; i < 20; ++i) {
    version2.cycle(record_of(static_cast<std::uint64_t>(i), i >= 10 ? SafeReason::PoseJump : SafeReason::None));
  }
  const std::vector<std::uint8_t>& old = version2.bytes();
  Seen seen;
  const JournalReadResult read = read_journal(old.data(), old.size(), seen.visitor());
  CHECK_TEXT(read.ok, read.error.c_str());
  LONGS_EQUAL(old.size(), read.good_bytes);
  LONGS_EQUAL(20, seen.cycles.size());
  for (int i = 0; i < 20; ++i) {
    const RecordedCycle& cycle = seen.cycles[static_cast<std::size_t>(i)];
    CHECK_TRUE(cycle.tool_recorded);
    CHECK_FALSE(cycle.maxima_recorded);  // version 5's
    JournalRecord want = record_of(static_cast<std::uint64_t>(i), i >= 10 ? SafeReason::PoseJump : SafeReason::None);
    check_same(want, cycle);
  }
  LONGS_EQUAL(1, seen.events.size());
  LONGS_EQUAL(1, seen.sources.size());
  CHECK(seen.sources[0] == stencil::control::CommandSource::Cycle);
}

// A record its version does not have is damage: Cycles before version 5, Provenance before version
// 4; and a Provenance record only right after its run's start or resume, once, its length holding
// its text.
TEST(JournalReader, ARecordItsVersionHasNoneOfOrOutOfItsPlaceIsAnErrorNamingTheOffset) {
  TempJournal file;
  write_job(file.path, 3);
  // A Cycles record in a version 4 journal is damage.
  std::vector<std::uint8_t> bytes = file.bytes();
  bytes[8] = 4;
  Seen mixed;
  JournalReadResult read = read_journal(bytes.data(), bytes.size(), mixed.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("a cycles record in a version 4 journal (version 5 has them)", read.error.c_str());

  // A provenance record in a version 3 journal is damage, named by its offset.
  {
    JournalWriter writer;
    JournalStart start = start_of();
    start.provenance = std::string(1, 'x');  // (not = "x": GCC 12 -O3 warns a false -Wrestrict)
    CHECK_TRUE(writer.open(file.path, start));
    CHECK_TRUE(writer.close());
  }
  bytes = file.bytes();
  bytes[8] = 3;
  Seen damaged;
  read = read_journal(bytes.data(), bytes.size(), damaged.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("a provenance record of 3 bytes in a version 3 journal", read.error.c_str());

  // Only right after its run's start or resume, once; its length must hold its text.
  {
    JournalWriter writer;
    JournalStart start = start_of();
    start.provenance = "made by";
    CHECK_TRUE(writer.open(file.path, start));
    CHECK_TRUE(writer.append(record_of(0)));
    CHECK_TRUE(writer.close());
  }
  bytes = file.bytes();
  const std::size_t start_record = kFileHeaderBytes;
  const std::size_t start_length = bytes[start_record] + (std::size_t{bytes[start_record + 1]} << 8U);
  const std::size_t provenance_at = start_record + kRecordOverheadBytes + start_length;
  const std::size_t provenance_length = kRecordOverheadBytes + 2 + 7;
  CHECK_EQUAL(static_cast<int>(RecordType::Provenance), bytes[provenance_at + 4]);
  std::vector<std::uint8_t> twice(bytes.begin(), bytes.begin() + static_cast<long>(provenance_at + provenance_length));
  twice.insert(twice.end(), bytes.begin() + static_cast<long>(provenance_at), bytes.end());
  Seen repeated;
  read = read_journal(twice.data(), twice.size(), repeated.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS(("journal offset " + std::to_string(provenance_at + provenance_length) +
                   ": a provenance record not right after a start or resume record").c_str(), read.error.c_str());
  std::vector<std::uint8_t> short_text = bytes;
  short_text[provenance_at + 5] = 9;  // the text's length: 9 of the 7 bytes there
  const uLong crc = crc32(crc32(0L, Z_NULL, 0), short_text.data() + provenance_at, static_cast<uInt>(5 + 2 + 7));
  for (int b = 0; b < 4; ++b) {
    short_text[provenance_at + 5 + 2 + 7 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(crc >> (8 * b));
  }
  Seen wrong;
  read = read_journal(short_text.data(), short_text.size(), wrong.visitor());
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("a provenance record of 9 bytes that does not hold its text", read.error.c_str());
}

// A run's cycles are all in one form; a Cycles record holds at least one. Anything else is damage.
TEST(JournalReader, ARunOfCompactCyclesWithAWholeCycleRecordOrAnEmptyCyclesRecordIsAnErrorNamingTheOffset) {
  TempJournal file;
  write_job(file.path, 3);
  const std::vector<std::uint8_t> whole = file.bytes();
  const auto appended = [&](RecordType type, const ByteWriter& payload) {
    ByteWriter record;
    record.u32(static_cast<std::uint32_t>(payload.size()));
    record.u8(static_cast<std::uint8_t>(type));
    record.bytes(payload.data(), payload.size());
    record.u32(static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), record.data(), static_cast<uInt>(record.size()))));
    std::vector<std::uint8_t> bytes = whole;
    bytes.insert(bytes.end(), record.data(), record.data() + record.size());
    return bytes;
  };
  ByteWriter cycle;
  encode_cycle(record_of(3), cycle);
  std::vector<std::uint8_t> bytes = appended(RecordType::Cycle, cycle);
  JournalReadResult read = read_journal(bytes.data(), bytes.size(), {});
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS(("journal offset " + std::to_string(whole.size()) + ": a cycle record of 106 bytes in a run of compact cycles").c_str(),
                  read.error.c_str());
  bytes = appended(RecordType::Cycles, ByteWriter{});
  read = read_journal(bytes.data(), bytes.size(), {});
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS("an empty cycles record (expected at least one cycle)", read.error.c_str());
}

TEST(JournalReader, ACommandRecordOutOfRangeIsAnErrorNamingTheOffset) {
  TempJournal file;
  JournalWriter writer;
  CHECK_TRUE(writer.open(file.path, start_of()));
  CHECK_TRUE(writer.append_command({1, 17, 0, stencil::control::CommandKind::Pause, stencil::control::CommandSource::Display,
                                    stencil::control::CommandOutcome::Done, 0.0, 0.0}));
  CHECK_TRUE(writer.close());
  std::vector<std::uint8_t> bytes = file.bytes();
  JournalVisitor offsets;
  std::vector<std::size_t> starts;
  offsets.offset = [&](std::size_t offset) { starts.push_back(offset); };
  CHECK_TRUE(read_journal(bytes.data(), bytes.size(), offsets).ok);
  const std::size_t at = starts.back();
  LONGS_EQUAL(static_cast<int>(RecordType::Command), bytes[at + 4]);
  bytes[at + 5 + 24] = 99;  // the kind
  const std::size_t length = 5 + kCommandPayloadBytes;
  const uLong crc = crc32(crc32(0L, Z_NULL, 0), bytes.data() + at, static_cast<uInt>(length));
  for (int b = 0; b < 4; ++b) {
    bytes[at + length + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(crc >> (8 * b));
  }
  const JournalReadResult read = read_journal(bytes.data(), bytes.size(), {});
  CHECK_FALSE(read.ok);
  STRCMP_CONTAINS(("journal offset " + std::to_string(at + 5 + 24) + ": a command record's kind is 99 (expected below 11)").c_str(),
                  read.error.c_str());
}
