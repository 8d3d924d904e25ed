// libFuzzer target: the journal reader takes any bytes. It either refuses them with an error naming
// an offset, or reads whole records and accounts for every byte (read, or the torn tail it ignored);
// every record it hands over keeps the format's promises.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <zlib.h>

#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

namespace {

// The same bytes with every record's CRC-32 made to match, so that the fuzzer gets past the CRC
// (which it can hardly ever forge) to the records' contents.
std::vector<std::uint8_t> with_good_crcs(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  std::size_t at = stencil::journal::kFileHeaderBytes;
  while (at + stencil::journal::kRecordOverheadBytes <= bytes.size()) {
    const std::uint32_t length = static_cast<std::uint32_t>(bytes[at]) | static_cast<std::uint32_t>(bytes[at + 1]) << 8 |
                                 static_cast<std::uint32_t>(bytes[at + 2]) << 16 | static_cast<std::uint32_t>(bytes[at + 3]) << 24;
    if (length > stencil::journal::kMaxPayloadBytes || at + stencil::journal::kRecordOverheadBytes + length > bytes.size()) {
      break;
    }
    const auto crc = static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), bytes.data() + at, 5 + length));
    for (int i = 0; i < 4; ++i) {
      bytes[at + 5 + length + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
    }
    at += stencil::journal::kRecordOverheadBytes + length;
  }
  return bytes;
}

int read_and_check(const std::uint8_t* data, std::size_t size);

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  read_and_check(data, size);
  const std::vector<std::uint8_t> fixed = with_good_crcs(data, size);
  return read_and_check(fixed.data(), fixed.size());
}

namespace {

int read_and_check(const std::uint8_t* data, std::size_t size) {
  // Every whole record read is announced by its offset and then handed over (a Cycles record as its
  // cycles, counted once); a refused record may be announced before it is refused.
  std::uint64_t visits = 0, offsets = 0;
  std::size_t record_at = 0, cycles_of = SIZE_MAX;
  const stencil::journal::JournalVisitor visitor{
      [&](const stencil::journal::JournalStart& start) {
        require(start.program.size() <= 256 && start.job.size() <= 1024);
        ++visits;
      },
      [&](const stencil::journal::RecordedCycle& c) {
        const stencil::control::JournalRecord& r = c.record;
        require(static_cast<int>(r.safe_reason) <= static_cast<int>(stencil::control::SafeReason::Stopped));
        require(static_cast<int>(r.read_status) <= static_cast<int>(stencil::hal::ReadStatus::Fault));
        require(static_cast<int>(r.read_reason) <= static_cast<int>(stencil::hal::HapticFault::HostWatchdogTripped));
        // A tool not recorded is NaN, never a guess; a recorded one is what its check says.
        require(c.tool_recorded || r.virtual_tip_mm[0] != r.virtual_tip_mm[0]);
        require(!c.tool_recorded || stencil::journal::tip_check(r.virtual_tip_mm) == c.tip_check);
        if (cycles_of != record_at) {  // a Cycles record holds many: its record counted once
          cycles_of = record_at;
          ++visits;
        }
      },
      [&](std::uint64_t, stencil::control::SafeReason reason) {
        require(reason != stencil::control::SafeReason::None);
        ++visits;
      },
      // The same safe-state record again, with its source: not another record.
      [&](std::uint64_t, stencil::control::SafeReason reason, stencil::control::CommandSource source) {
        require(reason != stencil::control::SafeReason::None);
        require(static_cast<int>(source) < stencil::control::kCommandSourceCount);
      },
      [&](const stencil::control::CommandEvent& e) {
        require(static_cast<int>(e.kind) < stencil::control::kCommandKindCount);
        require(static_cast<int>(e.source) < stencil::control::kCommandSourceCount);
        require(static_cast<int>(e.outcome) < stencil::control::kCommandOutcomeCount);
        require(e.asked == e.asked && e.applied == e.applied);  // not NaN
        ++visits;
      },
      [&](std::int64_t) { ++visits; },
      [&](const stencil::control::MachineCommandRecord& c) {
        for (int i = 0; i < 3; ++i) {
          require(c.order[i] <= 3);
          require(c.target_tip_mm[i] == c.target_tip_mm[i]);  // not NaN
        }
        ++visits;
      },
      [&](const stencil::journal::JournalResume& resume) {
        require(resume.program.size() <= 256);
        ++visits;
      },
      [&](std::uint64_t, stencil::control::SafeReason reason) {
        require(static_cast<int>(reason) <= static_cast<int>(stencil::control::SafeReason::Stopped));
        ++visits;
      },
      [&](std::size_t offset) {
        require(offset >= stencil::journal::kFileHeaderBytes && offset < size && (offsets == 0 || offset > record_at));
        record_at = offset;
        ++offsets;
      },
      [&](const std::string& text) {
        require(text.size() <= stencil::journal::kMaxProvenanceBytes);
        ++visits;
      }};
  const stencil::journal::JournalReadResult read = stencil::journal::read_journal(data, size, visitor);
  require(read.ok == read.error.empty());
  require(read.ok ? offsets == read.records && visits == read.records : offsets <= read.records + 1 && visits <= offsets);
  if (!read.ok) {
    require(read.error.rfind("journal offset ", 0) == 0);
    return 0;
  }
  require(read.good_bytes + read.tail_bytes == size);
  require((read.tail_bytes == 0) == read.tail.empty());
  return 0;
}

}  // namespace
