// Two journals of the same job compared byte for byte, apart from the start times in their Start
// and Resume records and those records' CRC-32s (which cover the times).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace stencil::same_behaviour {

struct JournalComparison {
  std::string error;                     // a journal that cannot be read, naming it and why: fails
  std::vector<std::string> differences;  // the first few records that differ, and how; any fails
  std::uint64_t records = 0;             // whole records in the older journal
  std::uint64_t start_times = 0;         // Start and Resume records whose time was left out
  std::uint64_t provenance = 0;          // Provenance records left out (both journals')
};

// Reads both with the project's journal reader (every record's length, type and CRC checked), then
// compares every byte except, in each Start and Resume record, its i64 start time and its CRC-32, and
// the Provenance records (which build wrote it, with what command line: not the job's behaviour).
[[nodiscard]] JournalComparison compare_journals(const std::string& older_path, const std::string& newer_path);

}  // namespace stencil::same_behaviour
