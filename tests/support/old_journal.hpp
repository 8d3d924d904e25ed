// A journal as versions 2 to 4 wrote it, one Cycle record of 106 bytes per cycle: the reader must
// still read such a file and carry versions 3 and 4 on, and stencil-same-behaviour still compares
// them. Today's writer writes version 5 only, so the tests make the old bytes here.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <zlib.h>

#include "firmware/services/journal/journal_bytes.hpp"
#include "firmware/services/journal/journal_format.hpp"

namespace stencil::testing {

class OldJournal {
 public:
  // The file header and the Start record (and, from version 4, a Provenance record when given).
  explicit OldJournal(std::uint32_t version, std::int64_t start_ns = 1'796'000'000'000'000'000,
                      const std::string& provenance = "", const std::string& program = "journal_tests",
                      const std::string& job = "pattern=raster seed=1")
      : version_(version) {
    journal::ByteWriter header;
    header.bytes(reinterpret_cast<const std::uint8_t*>(journal::kMagic), sizeof journal::kMagic);
    header.u32(version);
    bytes_.assign(header.data(), header.data() + header.size());
    journal::ByteWriter start;
    start.u32(0xdeadbeef);
    start.u32(92);
    start.i64(start_ns);
    start.u16(static_cast<std::uint16_t>(program.size()));
    start.bytes(reinterpret_cast<const std::uint8_t*>(program.data()), program.size());
    start.u16(static_cast<std::uint16_t>(job.size()));
    start.bytes(reinterpret_cast<const std::uint8_t*>(job.data()), job.size());
    add(journal::RecordType::Start, start);
    if (!provenance.empty()) {
      journal::ByteWriter text;
      text.u16(static_cast<std::uint16_t>(provenance.size()));
      text.bytes(reinterpret_cast<const std::uint8_t*>(provenance.data()), provenance.size());
      add(journal::RecordType::Provenance, text);
    }
  }

  // A cycle's record, and the safe-state record with the first in the safe state (the writer's rule).
  void cycle(const control::JournalRecord& r) {
    journal::ByteWriter payload;
    journal::encode_cycle(r, payload);
    add(journal::RecordType::Cycle, payload);
    if (r.safe_reason != control::SafeReason::None && !safe_) {
      journal::ByteWriter event;
      event.u64(r.cycle);
      event.u8(static_cast<std::uint8_t>(r.safe_reason));
      if (version_ > journal::kOldestVersion) {
        event.u8(0);  // the cycle's own
      }
      add(journal::RecordType::SafeState, event);
    }
    safe_ = r.safe_reason != control::SafeReason::None;
  }

  void end(std::uint64_t cycles) {
    journal::ByteWriter payload;
    payload.u64(cycles);
    payload.u8(0);
    add(journal::RecordType::End, payload);
  }

  void write(const std::string& path) const {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
  }
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  void add(journal::RecordType type, const journal::ByteWriter& payload) {
    journal::ByteWriter record;
    record.u32(static_cast<std::uint32_t>(payload.size()));
    record.u8(static_cast<std::uint8_t>(type));
    record.bytes(payload.data(), payload.size());
    record.u32(static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), record.data(), static_cast<uInt>(record.size()))));
    bytes_.insert(bytes_.end(), record.data(), record.data() + record.size());
  }
  std::vector<std::uint8_t> bytes_;
  std::uint32_t version_;
  bool safe_ = false;
};

}  // namespace stencil::testing
