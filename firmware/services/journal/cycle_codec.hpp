// The compact cycle (journal version 5): a cycle's record as what changed since the cycle before.
//
// A 1 kHz job wrote 115 bytes a cycle in version 4, most of them doubles that barely move. Here a
// cycle costs about 9: the device's position as micrometre steps (the PIO and CAN wires carry
// micrometres, and the in-process device rounds to them too, so the doubles are exactly steps), the
// virtual tool as a 32-bit check of its tip instead of the tip itself (a replay recomputes the tip
// and compares the check), and everything that did not change left out. The tool itself is written
// where something needs it: at a key (a run's first cycle and every kKeyEvery-th, all fields whole),
// and at every cycle whose touched set grew (the resume rebuilds the touched set from exactly those
// tips: a cycle whose count did not grow touched nothing new). The run's running maxima of force and
// offset are written when they rise, so a resumed job's report still covers its earlier runs.
//
// A cycle, in a Cycles record's payload (the records in a payload follow one another to its end):
//   u8 flags: 1 key, 2 fresh, 4 time, 8 counter, 16 device, 32 tool, 64 touched, 128 more.
//   Key: u64 cycle, i64 time_ns, f64 device_mm[3], f64 angles_rad[2], u32 sample_counter,
//        f64 virtual_tip_mm[3], f32 force_n[3], u32 touched, u16 status_bits, u8 safe_reason,
//        u8 read_status, u8 read_reason, f64 max_force_n, f64 max_offset_mm (fresh in the flags;
//        no other flag may be set with key).
//   Else, in this order, each only when its flag says so:
//     more: u8 more flags: 1 safe reason, 2 status bits, 4 read, 8 maxima, 16 cycle.
//     cycle (more 16): zigzag varint of cycle - (previous + 1); without it the next cycle.
//     time: zigzag varint of this cycle's time step less the step before; without it the same step.
//     counter: zigzag varint of counter - (previous + 1) (32-bit wrap); without it previous + 1.
//     device: u8 mask, two bits per position axis (bits 0-1 x, 2-3 y, 4-5 z) and bit 6 for the
//       angles (then a second u8 mask, bits 0-1 and 2-3 for the two angles); bit 7 is 0. Per field:
//       0 the same bits as before, 1 zigzag varint of steps - previous steps, 2 zigzag varint of
//       steps, 3 f64 as it is (a value that is no whole number of steps). A step is 1e-3 mm or
//       1e-6 rad, and the value is exactly steps * step. Without the device flag all are the same.
//     tool: f64 virtual_tip_mm[3], f32 force_n[3]; without it u32 CRC-32 of the tip's 24 bytes
//       (little-endian f64s) and no force.
//     touched: varint of touched - previous (more than 0); without it the same.
//     safe reason (more 1): u8. status bits (more 2): u16. read (more 4): u8 status, u8 reason.
//     maxima (more 8): f64 max_force_n, f64 max_offset_mm.
#pragma once

#include <cstdint>
#include <string>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/journal/journal_bytes.hpp"

namespace stencil::journal {

// A cycle as the journal gives it back.
struct RecordedCycle {
  control::JournalRecord record{};
  // record.virtual_tip_mm and force_n are the cycle's (a key, a cycle whose touched set grew, and
  // every cycle of a version 4 journal); else they are NaN and only tip_check stands for the tip.
  bool tool_recorded = true;
  // record.max_force_n and max_offset_mm are the run's so far (version 5); else 0.
  bool maxima_recorded = false;
  std::uint32_t tip_check = 0;  // CRC-32 of the tip (always: computed for a recorded tool)
};

// The check that stands for a virtual tool's tip: CRC-32 (zlib's) of its three little-endian f64s.
[[nodiscard]] std::uint32_t tip_check(const double tip_mm[3]);

// One run's cycles, written: each is encoded against the one before.
class CycleEncoder {
 public:
  static constexpr std::uint32_t kKeyEvery = 1000;  // a key a second at 1 kHz
  // A new run: its first cycle is a key, and its time steps count from 0 (as a new writer's do).
  void restart() {
    have_previous_ = false;
    previous_step_ns_ = 0;
  }
  void encode(const control::JournalRecord& record, ByteWriter& out);

 private:
  void encode_key(const control::JournalRecord& record, ByteWriter& out);
  bool have_previous_ = false;
  control::JournalRecord previous_{};
  std::int64_t previous_step_ns_ = 0;
  std::uint32_t since_key_ = 0;
};

// One run's cycles, read back: each decoded against the one before.
class CycleDecoder {
 public:
  void restart() {
    have_previous_ = false;
    previous_step_ns_ = 0;
  }
  // One cycle from `in`. False with `error` saying what was expected (the caller adds the offset).
  [[nodiscard]] bool decode(ByteReader& in, RecordedCycle& out, std::string& error);
  // A version 4 Cycle record read whole: the cycles after it (a version 4 journal carried on as
  // version 5) are not encoded against it (a run's first compact cycle is a key), so nothing to do
  // but remember that a key must come.
  void whole_record_read() { restart(); }

 private:
  [[nodiscard]] bool decode_key(ByteReader& in, std::uint8_t flags, RecordedCycle& out, std::string& error);
  bool have_previous_ = false;
  control::JournalRecord previous_{};
  std::int64_t previous_step_ns_ = 0;
};

}  // namespace stencil::journal
