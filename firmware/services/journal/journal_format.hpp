// The journal's bytes: what a job recorded, append-only, so that a crash loses at most the records
// not yet synced and never misreads a torn one.
//
// File: the magic "STENCILJ", a u32 version (5; 2 to 4 are read too), then records. All numbers little-endian.
// Record: u32 payload length, u8 type, the payload, u32 CRC-32 (zlib's) of the length, type and
// payload bytes. A reader stops at the first record that is incomplete or fails its CRC: that and
// everything after it is the torn tail of a crash, reported and ignored.
#pragma once

#include <cstddef>
#include <cstdint>

namespace stencil::journal {

inline constexpr char kMagic[8] = {'S', 'T', 'E', 'N', 'C', 'I', 'L', 'J'};
// 5: cycles compact (Cycles records, cycle_codec.hpp) instead of 115 bytes each (version 3 and 4
// journals are still carried on: their earlier runs' Cycle records stay as they are).
inline constexpr std::uint32_t kVersion = 5;
inline constexpr std::uint32_t kProvenanceVersion = 4;  // 4: Provenance records
inline constexpr std::uint32_t kCompactVersion = 5;
inline constexpr std::uint32_t kOldestVersion = 2;  // no Command records, a SafeState without its source
inline constexpr std::size_t kFileHeaderBytes = 12;
inline constexpr std::size_t kRecordOverheadBytes = 9;  // length, type, CRC
// No record is longer; a length over this is a torn or damaged record, not a reason to allocate.
inline constexpr std::uint32_t kMaxPayloadBytes = 4096;

enum class RecordType : std::uint8_t {
  Start = 1,      // the job: which tables, when, which program
  Cycle = 2,      // one cycle: the device sample it read and the virtual tool it left (versions 2 to 4)
  SafeState = 3,  // the cycle entered its safe state (synced at once)
  Homed = 4,      // the machine homed: its tool is at home from here (written through at once)
  MachineCommand = 5,  // a target: queued by the machine thread, written through by the records
                       // thread, and sent only once written (a crash cannot lose one that was sent)
  Resume = 6,     // a resumed job's next segment starts here (its cycles count from 0 again)
  End = 7,        // the run ended in order (a run without one was killed or crashed)
  Command = 8,    // a command the cycle took (a stop, a reset, a pause, a parameter): before its cycle's record
  Provenance = 9, // what made this run: right after its Start or Resume (version 4)
  Cycles = 10,    // consecutive cycles, compact (version 5): the writer ends one before any other record
};

// Payload of Start: u32 tables' CRC-32, u32 triangle count, i64 start (ns since the Unix epoch),
// u16 program name length and its bytes, u16 job length and its bytes (what the program needs to
// carry the same job on: a simulation's pattern and stock, for instance).
// Payload of Cycle (106 bytes): u64 cycle, i64 time_ns, f64 device_mm[3], f64 angles_rad[2],
// u32 sample_counter, u8 fresh, f64 virtual_tip_mm[3], u8 safe_reason, u32 touched_triangles,
// f32 force_n[3], u16 status_bits, u8 read_status (hal::ReadStatus), u8 read_reason (hal::HapticFault).
inline constexpr std::uint32_t kCyclePayloadBytes = 8 + 8 + 24 + 16 + 4 + 1 + 24 + 1 + 4 + 12 + 2 + 1 + 1;
static_assert(kCyclePayloadBytes == 106, "the Cycle payload the comment above lays out");
// Payload of Cycles: compact cycles one after another to the payload's end (cycle_codec.hpp), each
// against the one before in its run, across records; a run's first is a key. The writer ends a
// Cycles record before any other record, so the order of a cycle and a command or machine target is
// the file's order; it ends one too after 100 cycles or 3800 bytes (never on the clock, so a job's
// bytes are the same every time), and a sync writes the records ended so far.
inline constexpr std::uint32_t kCyclesPerRecord = 100;
inline constexpr std::uint32_t kCyclesRecordBytes = 3800;
// Payload of SafeState: u64 cycle, u8 reason (control::SafeReason), u8 source (control::CommandSource:
// where a stop came from; version 2 has no source).
inline constexpr std::uint32_t kSafeStatePayloadBytes = 10;
inline constexpr std::uint32_t kSafeStateV2PayloadBytes = 9;
// Payload of Command (43 bytes): u64 cycle (that took it), i64 time_ns, u64 queued_after_cycle, u8 kind
// (control::CommandKind), u8 source (control::CommandSource), u8 outcome (control::CommandOutcome),
// f64 asked, f64 applied (a parameter's value asked and in force after, its command's unit; else 0).
inline constexpr std::uint32_t kCommandPayloadBytes = 8 + 8 + 8 + 1 + 1 + 1 + 8 + 8;
static_assert(kCommandPayloadBytes == 43, "the Command payload the comment above lays out");
// Payload of Homed: i64 time_ns (the machine's clock).
inline constexpr std::uint32_t kHomedPayloadBytes = 8;
// Payload of MachineCommand (55 bytes): u64 update, i64 time_ns, i32 motor_target[3], u8 order[3]
// (each 0-2, or 3 for no leg), f64 target_tip_mm[3].
inline constexpr std::uint32_t kMachineCommandPayloadBytes = 8 + 8 + 12 + 3 + 24;
// Payload of End: u64 cycles the run made, u8 the safe reason it ended in (0: none, it finished).
inline constexpr std::uint32_t kEndPayloadBytes = 9;
// Payload of Provenance: u16 length and that many bytes of text (report::provenance_line: the program,
// its version and compiler, the configuration's CRC-32, the tables' identity, the command line).
inline constexpr std::size_t kMaxProvenanceBytes = 4000;
// Payload of Resume: u32 segment (1 for the first resume), i64 start (ns since the Unix epoch),
// f64 script_s and f64 approach_s (a simulated operator's: where its script carries on and how long
// the way back to the cut takes first; 0 for a person), u16 program name length and its bytes.

}  // namespace stencil::journal
