// The journal's bytes: what a job recorded, append-only, so that a crash loses at most the records
// not yet synced and never misreads a torn one.
//
// File: the magic "STENCILJ", a u32 version (1), then records. All numbers little-endian.
// Record: u32 payload length, u8 type, the payload, u32 CRC-32 (zlib's) of the length, type and
// payload bytes. A reader stops at the first record that is incomplete or fails its CRC: that and
// everything after it is the torn tail of a crash, reported and ignored.
#pragma once

#include <cstddef>
#include <cstdint>

namespace stencil::journal {

inline constexpr char kMagic[8] = {'S', 'T', 'E', 'N', 'C', 'I', 'L', 'J'};
inline constexpr std::uint32_t kVersion = 1;
inline constexpr std::size_t kFileHeaderBytes = 12;
inline constexpr std::size_t kRecordOverheadBytes = 9;  // length, type, CRC
// No record is longer; a length over this is a torn or damaged record, not a reason to allocate.
inline constexpr std::uint32_t kMaxPayloadBytes = 4096;

enum class RecordType : std::uint8_t {
  Start = 1,      // the job: which tables, when, which program
  Cycle = 2,      // one cycle: the device sample it read and the virtual tool it left
  SafeState = 3,  // the cycle entered its safe state (synced at once)
};

// Payload of Start: u32 tables' CRC-32, u32 triangle count, i64 start (ns since the Unix epoch),
// u16 program name length and its bytes.
// Payload of Cycle (86 bytes): u64 cycle, i64 time_ns, f64 device_mm[3], f64 angles_rad[2],
// u32 sample_counter, u8 fresh, f64 virtual_tip_mm[3], u8 safe_reason.
inline constexpr std::uint32_t kCyclePayloadBytes = 8 + 8 + 24 + 16 + 4 + 1 + 24 + 1;
// Payload of SafeState: u64 cycle, u8 reason (control::SafeReason).
inline constexpr std::uint32_t kSafeStatePayloadBytes = 9;

}  // namespace stencil::journal
