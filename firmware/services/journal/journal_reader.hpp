// Reading a journal back: every whole record in order, up to the first that is incomplete or fails
// its CRC (the torn tail of a crash: reported, never misread).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <functional>
#include <string>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/journal/cycle_codec.hpp"
#include "firmware/services/journal/journal_writer.hpp"

namespace stencil::journal {

struct JournalVisitor {
  std::function<void(const JournalStart&)> start;
  // Every cycle, from a Cycle record (versions 2 to 4) or a Cycles record (version 5).
  std::function<void(const RecordedCycle&)> cycle;
  std::function<void(std::uint64_t cycle, control::SafeReason)> safe_state;
  // The same record with where it came from (version 2: CommandSource::Cycle).
  std::function<void(std::uint64_t cycle, control::SafeReason, control::CommandSource)> safe_source;
  std::function<void(const control::CommandEvent&)> command;
  std::function<void(std::int64_t time_ns)> homed;
  std::function<void(const control::MachineCommandRecord&)> machine_command;
  std::function<void(const JournalResume&)> resume;
  std::function<void(std::uint64_t cycles, control::SafeReason reason)> end;
  std::function<void(std::size_t offset)> offset;  // before each whole record's own callback: where it starts
  std::function<void(const std::string& provenance)> provenance;  // after its run's start or resume
};

struct JournalReadResult {
  bool ok = false;            // the header was good and every record before the tail read
  std::string error;          // why not: names the offset and what was expected
  std::uint64_t records = 0;  // whole records read
  std::size_t good_bytes = 0;   // the journal up to the end of the last whole record
  std::size_t tail_bytes = 0;   // ignored after it: a torn last record (0 for a clean end)
  std::string tail;           // what was wrong with the first ignored record, when there is a tail
};

// Reads `size` bytes. A bad file header or a whole record that makes no sense (an unknown type, a
// wrong length for its type, a safe reason out of range) is an error: that is not a crash's doing.
[[nodiscard]] JournalReadResult read_journal(const std::uint8_t* data, std::size_t size, const JournalVisitor& visit);

// The same from a file, its first `limit_bytes` at most; an unreadable file is an error naming it.
[[nodiscard]] JournalReadResult read_journal_file(const std::string& path, const JournalVisitor& visit,
                                                  std::size_t limit_bytes = std::numeric_limits<std::size_t>::max());

}  // namespace stencil::journal
