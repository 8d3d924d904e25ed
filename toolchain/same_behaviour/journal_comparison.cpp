// Journal comparison: the reader finds the records, the times are masked where the format puts them.
#include "toolchain/same_behaviour/journal_comparison.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "firmware/services/journal/journal_bytes.hpp"
#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/journal/journal_reader.hpp"

namespace stencil::same_behaviour {
namespace {

using journal::RecordType;

// Where the start time sits in a payload (firmware/services/journal/journal_format.hpp): after the tables'
// CRC-32 and triangle count in a Start record, after the segment in a Resume record. Checked
// against the reader's own reading of the time below, so a changed layout is an error, not a
// mask over the wrong bytes.
constexpr std::size_t kStartTimeInStart = 4 + 4;
constexpr std::size_t kStartTimeInResume = 4;
constexpr std::size_t kStartTimeBytes = 8;
constexpr std::size_t kRecordHeadBytes = 5;  // u32 payload length, u8 type; then the payload, then the CRC
constexpr std::size_t kCrcBytes = 4;
constexpr std::size_t kMostDifferencesShown = 5;

struct Record {
  std::size_t offset = 0;  // of its length field in the file
  std::uint32_t length = 0;
  RecordType type{};
  std::size_t masked_from = 0, masked_to = 0;  // file offsets of the start time, or none (equal)
};

struct Journal {
  std::vector<std::uint8_t> bytes;
  std::vector<Record> records;  // every whole record but the Provenance ones (the build's, not the job's)
  std::uint64_t provenance = 0;
  std::uint32_t version = 0;
  std::size_t good_bytes = 0;  // the rest is a torn tail, compared as plain bytes
};

const char* type_name(RecordType type) {
  switch (type) {
    case RecordType::Start: return "start";
    case RecordType::Cycle: return "cycle";
    case RecordType::SafeState: return "safe-state";
    case RecordType::Homed: return "homed";
    case RecordType::MachineCommand: return "machine command";
    case RecordType::Resume: return "resume";
    case RecordType::End: return "end";
    case RecordType::Command: return "command";
    case RecordType::Provenance: return "provenance";
    case RecordType::Cycles: return "cycles";
  }
  return "unknown";
}

// The journal's records, each with its start time located; "" or why it cannot be compared.
std::string load(const std::string& path, Journal& journal) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  std::ifstream in(path, std::ios::binary);
  if (error || !in) {
    return path + ": cannot be read";
  }
  journal.bytes.resize(static_cast<std::size_t>(size));
  if (!in.read(reinterpret_cast<char*>(journal.bytes.data()), static_cast<std::streamsize>(size))) {
    return path + ": cannot be read";
  }
  std::map<std::size_t, std::int64_t> start_times;  // by record offset, as the reader read them
  std::vector<std::size_t> offsets;
  journal::JournalVisitor visit;
  visit.offset = [&](std::size_t offset) { offsets.push_back(offset); };
  visit.start = [&](const journal::JournalStart& start) { start_times[offsets.back()] = start.unix_time_ns; };
  visit.resume = [&](const journal::JournalResume& resume) { start_times[offsets.back()] = resume.unix_time_ns; };
  const journal::JournalReadResult result = journal::read_journal(journal.bytes.data(), journal.bytes.size(), visit);
  if (!result.ok) {
    return path + ": " + result.error;
  }
  journal.good_bytes = result.good_bytes;
  journal::ByteReader version(journal.bytes.data() + sizeof journal::kMagic, 4);
  journal.version = version.u32();
  for (const std::size_t offset : offsets) {
    journal::ByteReader head(journal.bytes.data() + offset, journal.bytes.size() - offset);
    Record record;
    record.offset = offset;
    record.length = head.u32();
    record.type = static_cast<RecordType>(head.u8());
    if (record.type == RecordType::Provenance) {
      ++journal.provenance;
      continue;
    }
    if (record.type == RecordType::Start || record.type == RecordType::Resume) {
      const std::size_t payload = offset + kRecordHeadBytes;
      record.masked_from = payload + (record.type == RecordType::Start ? kStartTimeInStart : kStartTimeInResume);
      record.masked_to = record.masked_from + kStartTimeBytes;
      journal::ByteReader time(journal.bytes.data() + record.masked_from, kStartTimeBytes);
      const auto read = start_times.find(offset);
      if (read == start_times.end() || time.i64() != read->second) {
        return path + ": journal offset " + std::to_string(offset) + ": the " + type_name(record.type) +
               " record's time is not where journal_format.hpp puts it (this tool's layout is out of date)";
      }
    }
    journal.records.push_back(record);
  }
  return "";
}

// The first byte of record `ra` (its first `count` bytes) where it differs from `rb`, leaving out the
// record's start time, as a file offset in `a`; `ra.offset + count` if none. The two may sit at
// different offsets (one journal has Provenance records the other has not).
std::size_t first_difference(const Journal& a, const Journal& b, const Record& ra, const Record& rb, std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = ra.offset + k;
    if (i >= ra.masked_from && i < ra.masked_to) {
      continue;
    }
    if (a.bytes[i] != b.bytes[rb.offset + k]) {
      return i;
    }
  }
  return ra.offset + count;
}

std::string describe(const Journal& journal, std::size_t index, const Record& record) {
  std::string text = "record " + std::to_string(index) + " (" + type_name(record.type);
  if (record.type == RecordType::Cycle) {
    journal::ByteReader payload(journal.bytes.data() + record.offset + kRecordHeadBytes, record.length);
    text += " " + std::to_string(payload.u64());
  }
  return text + ") at offset " + std::to_string(record.offset);
}

// Which part of the record the file offset `at` falls in, for a message.
std::string part_at(const Record& record, std::size_t at) {
  const std::size_t payload = record.offset + kRecordHeadBytes;
  if (at < payload) {
    return "its length or type";
  }
  if (at < payload + record.length) {
    return "its payload from byte " + std::to_string(at - payload) + " (of " + std::to_string(record.length) + ")";
  }
  return "its CRC-32";
}

// The file header and every compared record: the whole records' bytes but the Provenance ones.
std::size_t records_bytes(const Journal& journal) {
  std::size_t bytes = journal::kFileHeaderBytes;
  for (const Record& record : journal.records) {
    bytes += journal::kRecordOverheadBytes + record.length;
  }
  return bytes;
}

}  // namespace

JournalComparison compare_journals(const std::string& older_path, const std::string& newer_path) {
  JournalComparison out;
  Journal older;
  Journal newer;
  out.error = load(older_path, older);
  if (out.error.empty()) {
    out.error = load(newer_path, newer);
  }
  if (!out.error.empty()) {
    return out;
  }
  out.records = older.records.size();
  // The reader accepted both headers. Versions 3 and 4 differ only in 4's Provenance records, which
  // say which build wrote the file and are left out; any other difference of versions is one.
  const bool provenance_step = std::min(older.version, newer.version) + 1 == journal::kProvenanceVersion &&
                               std::max(older.version, newer.version) == journal::kProvenanceVersion;
  if (older.version != newer.version && !provenance_step) {
    out.differences.push_back("the file versions differ: " + std::to_string(older.version) + " and " +
                              std::to_string(newer.version));
  }
  out.provenance = older.provenance + newer.provenance;
  std::size_t differing = 0;
  const std::size_t common = std::min(older.records.size(), newer.records.size());
  for (std::size_t i = 0; i < common; ++i) {
    const Record& a = older.records[i];
    const Record& b = newer.records[i];
    if (a.length != b.length || a.type != b.type) {
      out.differences.push_back(describe(older, i, a) + " in the older, " + describe(newer, i, b) + " in the newer (" +
                                std::to_string(a.length) + " and " + std::to_string(b.length) +
                                " payload bytes); the records after it are not compared");
      return out;
    }
    if (a.type == RecordType::Start || a.type == RecordType::Resume) {
      ++out.start_times;
    }
    // The whole record, length to CRC; a Start or Resume record's CRC covers its time, so it is left out too.
    const bool timed = a.masked_to > a.masked_from;
    const std::size_t count = journal::kRecordOverheadBytes + a.length - (timed ? kCrcBytes : 0);
    const std::size_t end = a.offset + count;
    const std::size_t at = first_difference(older, newer, a, b, count);
    if (at != end && ++differing <= kMostDifferencesShown) {
      out.differences.push_back(describe(older, i, a) + ": " + part_at(a, at) + " differs");
    }
  }
  if (differing > kMostDifferencesShown) {
    out.differences.push_back(std::to_string(differing) + " records differ in all");
  }
  if (older.records.size() != newer.records.size()) {
    out.differences.push_back(std::to_string(older.records.size()) + " records in the older, " +
                              std::to_string(newer.records.size()) + " in the newer");
  }
  // What follows the last whole record (a torn tail, normally nothing) must be the same bytes.
  const bool same_tail = older.bytes.size() - older.good_bytes == newer.bytes.size() - newer.good_bytes &&
                         std::equal(older.bytes.begin() + static_cast<std::ptrdiff_t>(older.good_bytes), older.bytes.end(),
                                    newer.bytes.begin() + static_cast<std::ptrdiff_t>(newer.good_bytes));
  if (!same_tail) {
    out.differences.push_back("the torn tails differ: " + std::to_string(older.bytes.size() - older.good_bytes) + " and " +
                              std::to_string(newer.bytes.size() - newer.good_bytes) + " bytes after the last whole record");
  }
  const std::size_t provenance_bytes_older = older.good_bytes - records_bytes(older);
  const std::size_t provenance_bytes_newer = newer.good_bytes - records_bytes(newer);
  if (older.bytes.size() - provenance_bytes_older != newer.bytes.size() - provenance_bytes_newer) {
    out.differences.push_back(std::to_string(older.bytes.size()) + " bytes in the older, " + std::to_string(newer.bytes.size()) +
                              " in the newer");
  }
  return out;
}

}  // namespace stencil::same_behaviour
