// What the journal's suites share (journal_writer, journal_reader, journal_drain, job_journal,
// job_history): a record whose every field moves with its cycle, a temporary file, a visitor that
// keeps everything it is shown, and a bit-for-bit comparison of a record with its reading.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/machine_record.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"

namespace stencil::testing {

// Cycle `cycle`'s record: every field a function of the cycle, so a misplaced one shows.
[[nodiscard]] control::JournalRecord record_of(std::uint64_t cycle,
                                               control::SafeReason reason = control::SafeReason::None);

// A fresh empty file under /tmp, removed with the object.
struct TempJournal {
  std::string path;
  TempJournal();
  ~TempJournal();
  TempJournal(const TempJournal&) = delete;
  TempJournal& operator=(const TempJournal&) = delete;
  [[nodiscard]] std::vector<std::uint8_t> bytes() const;
};

// The Start record the suites write: tables 0xdeadbeef of 92 triangles.
[[nodiscard]] journal::JournalStart start_of();

// Writes `cycles` records (the last `safe_from` onward in the safe state) and closes.
void write_job(const std::string& path, int cycles, int safe_from = -1);

// Everything a read shows, kept.
struct Seen {
  int starts = 0;
  std::vector<journal::RecordedCycle> cycles;
  std::vector<std::pair<std::uint64_t, control::SafeReason>> events;
  std::vector<std::int64_t> homings;
  std::vector<control::MachineCommandRecord> commands;
  std::vector<journal::JournalResume> resumes;
  std::vector<std::pair<std::uint64_t, control::SafeReason>> endings;
  journal::JournalStart start;
  std::vector<control::CommandSource> sources;  // each safe state's
  std::vector<control::CommandEvent> taken;     // the cycle's commands
  std::vector<std::string> provenances;
  journal::JournalVisitor visitor();
};

// `seen` is `a` as written: bit for bit (a replay must be exact), its tool whole or its check.
void check_same(const control::JournalRecord& a, const journal::RecordedCycle& seen);

// Where each whole record starts, and where the last one ends.
[[nodiscard]] std::vector<std::size_t> record_starts(const std::vector<std::uint8_t>& bytes);

// Machine target `update`: its Y moving with it.
[[nodiscard]] control::MachineCommandRecord command_of(std::uint64_t update);

}  // namespace stencil::testing
