// The compact cycle: what changed, in as few bytes as it takes.
#include "firmware/services/journal/cycle_codec.hpp"

#include <cmath>
#include <cstring>
#include <limits>

#include <zlib.h>

#include "firmware/core/control/safe_state.hpp"

namespace stencil::journal {
namespace {

enum Flag : std::uint8_t { kKey = 1, kFresh = 2, kTime = 4, kCounter = 8, kDevice = 16, kTool = 32, kTouched = 64, kMore = 128 };
enum More : std::uint8_t { kSafe = 1, kStatus = 2, kRead = 4, kMaxima = 8, kCycle = 16, kKnownMore = 31 };
enum Field : std::uint8_t { kSame = 0, kStepDelta = 1, kSteps = 2, kRaw = 3 };
constexpr std::uint8_t kAnglesFollow = 0x40;

// Device fields: three positions in micrometres, two angles in microradians.
constexpr int kFields = 5;
constexpr double kStepsPerUnit[kFields] = {1e3, 1e3, 1e3, 1e6, 1e6};
constexpr double kUnitPerStep[kFields] = {1e-3, 1e-3, 1e-3, 1e-6, 1e-6};
constexpr const char* kFieldName[kFields] = {"device x", "device y", "device z", "angle 0", "angle 1"};
// Steps beyond this are not counted (the doubles stay exact well inside it, and no device reaches it).
constexpr double kMostSteps = 4.0e15;

double& field(control::JournalRecord& r, int i) { return i < 3 ? r.device_mm[i] : r.angles_rad[i - 3]; }
double field(const control::JournalRecord& r, int i) { return i < 3 ? r.device_mm[i] : r.angles_rad[i - 3]; }

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

double from_steps(std::int64_t steps, int i) { return static_cast<double>(steps) * kUnitPerStep[i]; }

// The value as whole steps, when from_steps gives it back bit for bit (as the wires' decoders make
// it; -0 is not, it comes back +0).
bool as_steps(double value, int i, std::int64_t& steps) {
  const double rounded = std::round(value * kStepsPerUnit[i]);
  if (!(std::fabs(rounded) < kMostSteps)) {
    return false;
  }
  steps = static_cast<std::int64_t>(rounded);
  return same_bits(from_steps(steps, i), value);
}

// Sums that wrap rather than overflow: a damaged journal's numbers are not trusted to stay in range.
std::int64_t wrapping_sum(std::int64_t a, std::int64_t b) {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(a) + static_cast<std::uint64_t>(b));
}

std::int64_t wrapping_difference(std::int64_t a, std::int64_t b) {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(a) - static_cast<std::uint64_t>(b));
}

constexpr std::uint8_t bit_if(bool set, std::uint8_t bit) { return set ? bit : std::uint8_t{0}; }

bool valid_read(std::uint8_t status, std::uint8_t reason) {
  return status <= static_cast<std::uint8_t>(hal::ReadStatus::Fault) &&
         reason <= static_cast<std::uint8_t>(hal::HapticFault::HostWatchdogTripped);
}

void write_tool(const control::JournalRecord& r, ByteWriter& out) {
  for (const double v : r.virtual_tip_mm) {
    out.f64(v);
  }
  for (const float v : r.force_n) {
    out.f32(v);
  }
}

void read_tool(ByteReader& in, control::JournalRecord& r) {
  for (double& v : r.virtual_tip_mm) {
    v = in.f64();
  }
  for (float& v : r.force_n) {
    v = in.f32();
  }
}

}  // namespace

// On the stack: a replay computes it in its cycle's hook, where nothing allocates.
std::uint32_t tip_check(const double tip_mm[3]) {
  std::uint8_t bytes[24];
  for (int i = 0; i < 3; ++i) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &tip_mm[i], sizeof bits);
    for (int b = 0; b < 8; ++b) {
      bytes[8 * i + b] = static_cast<std::uint8_t>(bits >> (8 * b));
    }
  }
  return static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), bytes, sizeof bytes));
}

void CycleEncoder::encode_key(const control::JournalRecord& r, ByteWriter& out) {
  out.u8(static_cast<std::uint8_t>(kKey | (r.fresh ? kFresh : 0)));
  out.u64(r.cycle);
  out.i64(r.time_ns);
  for (int i = 0; i < kFields; ++i) {
    out.f64(field(r, i));
  }
  out.u32(r.sample_counter);
  write_tool(r, out);
  out.u32(r.touched_triangles);
  out.u16(r.status_bits);
  out.u8(static_cast<std::uint8_t>(r.safe_reason));
  out.u8(static_cast<std::uint8_t>(r.read_status));
  out.u8(static_cast<std::uint8_t>(r.read_reason));
  out.f64(r.max_force_n);
  out.f64(r.max_offset_mm);
}

void CycleEncoder::encode(const control::JournalRecord& r, ByteWriter& out) {
  const control::JournalRecord& p = previous_;
  if (!have_previous_ || ++since_key_ >= kKeyEvery || r.touched_triangles < p.touched_triangles) {
    encode_key(r, out);
    have_previous_ = true;
    since_key_ = 0;
    previous_ = r;
    return;
  }
  std::uint8_t flags = bit_if(r.fresh, kFresh);
  std::uint8_t more = 0;
  const std::int64_t step_ns = wrapping_difference(r.time_ns, p.time_ns);
  flags |= bit_if(step_ns != previous_step_ns_, kTime);
  flags |= bit_if(r.sample_counter != p.sample_counter + 1U, kCounter);
  std::uint8_t codes[kFields] = {};
  std::int64_t steps[kFields] = {};
  for (int i = 0; i < kFields; ++i) {
    std::int64_t before = 0;
    if (same_bits(field(r, i), field(p, i))) {
      codes[i] = kSame;
    } else if (!as_steps(field(r, i), i, steps[i])) {
      codes[i] = kRaw;
    } else if (as_steps(field(p, i), i, before) && std::fabs(static_cast<double>(steps[i] - before)) < kMostSteps) {
      codes[i] = kStepDelta;
      steps[i] -= before;
    } else {
      codes[i] = kSteps;
    }
    flags |= bit_if(codes[i] != kSame, kDevice);
  }
  // The tool whole where the touched set grew (the resume rebuilds the set from those tips) or the
  // safe state changed (where a reader looks for it).
  const bool grew = r.touched_triangles != p.touched_triangles;
  flags |= bit_if(grew || r.safe_reason != p.safe_reason, kTool);
  flags |= bit_if(grew, kTouched);
  more |= bit_if(r.safe_reason != p.safe_reason, kSafe);
  more |= bit_if(r.status_bits != p.status_bits, kStatus);
  more |= bit_if(r.read_status != p.read_status || r.read_reason != p.read_reason, kRead);
  more |= bit_if(!same_bits(r.max_force_n, p.max_force_n) || !same_bits(r.max_offset_mm, p.max_offset_mm), kMaxima);
  more |= bit_if(r.cycle != p.cycle + 1, kCycle);
  flags |= bit_if(more != 0, kMore);

  out.u8(flags);
  if (more != 0) {
    out.u8(more);
  }
  if ((more & kCycle) != 0) {
    out.zigzag(static_cast<std::int64_t>(r.cycle - (p.cycle + 1)));
  }
  if ((flags & kTime) != 0) {
    out.zigzag(wrapping_difference(step_ns, previous_step_ns_));
  }
  if ((flags & kCounter) != 0) {
    out.zigzag(static_cast<std::int32_t>(r.sample_counter - (p.sample_counter + 1U)));
  }
  if ((flags & kDevice) != 0) {
    const bool angles = codes[3] != kSame || codes[4] != kSame;
    out.u8(static_cast<std::uint8_t>(codes[0] | codes[1] << 2U | codes[2] << 4U | (angles ? kAnglesFollow : 0)));
    if (angles) {
      out.u8(static_cast<std::uint8_t>(codes[3] | codes[4] << 2U));
    }
    for (int i = 0; i < kFields; ++i) {
      if (codes[i] == kRaw) {
        out.f64(field(r, i));
      } else if (codes[i] != kSame) {
        out.zigzag(steps[i]);
      }
    }
  }
  if ((flags & kTool) != 0) {
    write_tool(r, out);
  } else {
    out.u32(tip_check(r.virtual_tip_mm));
  }
  if ((flags & kTouched) != 0) {
    out.varint(r.touched_triangles - p.touched_triangles);
  }
  if ((more & kSafe) != 0) {
    out.u8(static_cast<std::uint8_t>(r.safe_reason));
  }
  if ((more & kStatus) != 0) {
    out.u16(r.status_bits);
  }
  if ((more & kRead) != 0) {
    out.u8(static_cast<std::uint8_t>(r.read_status));
    out.u8(static_cast<std::uint8_t>(r.read_reason));
  }
  if ((more & kMaxima) != 0) {
    out.f64(r.max_force_n);
    out.f64(r.max_offset_mm);
  }
  previous_step_ns_ = step_ns;
  previous_ = r;
}

bool CycleDecoder::decode_key(ByteReader& in, std::uint8_t flags, RecordedCycle& out, std::string& error) {
  control::JournalRecord& r = out.record;
  if ((flags & ~(kKey | kFresh)) != 0) {
    error = "a key cycle's flags " + std::to_string(flags) + " (a key has only the fresh flag beside it)";
    return false;
  }
  r.fresh = (flags & kFresh) != 0;
  r.cycle = in.u64();
  r.time_ns = in.i64();
  for (int i = 0; i < kFields; ++i) {
    field(r, i) = in.f64();
  }
  r.sample_counter = in.u32();
  read_tool(in, r);
  r.touched_triangles = in.u32();
  r.status_bits = in.u16();
  const std::uint8_t reason = in.u8();
  const std::uint8_t status = in.u8();
  const std::uint8_t read_reason = in.u8();
  r.max_force_n = in.f64();
  r.max_offset_mm = in.f64();
  if (in.overrun()) {
    error = "a key cycle cut short";
    return false;
  }
  if (!control::is_safe_reason_byte(reason) || !valid_read(status, read_reason)) {
    error = "a key cycle's safe reason " + std::to_string(reason) + ", read status " + std::to_string(status) +
            " or read reason " + std::to_string(read_reason) + " is out of range";
    return false;
  }
  r.safe_reason = static_cast<control::SafeReason>(reason);
  r.read_status = static_cast<hal::ReadStatus>(status);
  r.read_reason = static_cast<hal::HapticFault>(read_reason);
  out.tool_recorded = true;
  out.maxima_recorded = true;
  out.tip_check = tip_check(r.virtual_tip_mm);
  have_previous_ = true;
  previous_ = r;
  return true;
}

bool CycleDecoder::decode(ByteReader& in, RecordedCycle& out, std::string& error) {
  out = RecordedCycle{};
  const std::uint8_t flags = in.u8();
  if ((flags & kKey) != 0) {
    return decode_key(in, flags, out, error);
  }
  if (!have_previous_) {
    error = "a cycle with no key cycle before it in its run (a run's first cycle is a key)";
    return false;
  }
  const control::JournalRecord& p = previous_;
  control::JournalRecord& r = out.record;
  r = p;
  r.fresh = (flags & kFresh) != 0;
  const std::uint8_t more = (flags & kMore) != 0 ? in.u8() : 0;
  if ((more & ~kKnownMore) != 0) {
    error = "a cycle's second flags byte " + std::to_string(more) + " (expected bits 1 to 16 only)";
    return false;
  }
  r.cycle = p.cycle + 1 + ((more & kCycle) != 0 ? static_cast<std::uint64_t>(in.zigzag()) : 0U);
  const std::int64_t step_ns = wrapping_sum(previous_step_ns_, (flags & kTime) != 0 ? in.zigzag() : 0);
  r.time_ns = wrapping_sum(p.time_ns, step_ns);
  r.sample_counter = p.sample_counter + 1U + ((flags & kCounter) != 0 ? static_cast<std::uint32_t>(in.zigzag()) : 0U);
  if ((flags & kDevice) != 0) {
    const std::uint8_t positions = in.u8();
    const std::uint8_t angles = (positions & kAnglesFollow) != 0 ? in.u8() : 0;
    if ((positions & 0x80U) != 0 || (angles & 0xF0U) != 0) {
      error = "a cycle's device masks " + std::to_string(positions) + " and " + std::to_string(angles) +
              " set bits no field has";
      return false;
    }
    for (int i = 0; i < kFields; ++i) {
      const auto code = static_cast<std::uint8_t>(i < 3 ? (positions >> (2 * i)) & 3U : (angles >> (2 * (i - 3))) & 3U);
      std::int64_t before = 0;
      if (code == kRaw) {
        field(r, i) = in.f64();
      } else if (code == kSteps) {
        field(r, i) = from_steps(in.zigzag(), i);
      } else if (code == kStepDelta) {
        if (!as_steps(field(p, i), i, before)) {
          error = std::string("a cycle's ") + kFieldName[i] + " given as steps from one before that is no whole number of " +
                  (i < 3 ? "micrometres" : "microradians") + " (expected code 2 or 3 then)";
          return false;
        }
        const std::int64_t delta = in.zigzag();
        if (delta > static_cast<std::int64_t>(kMostSteps) || delta < -static_cast<std::int64_t>(kMostSteps)) {
          error = std::string("a cycle's ") + kFieldName[i] + " moved " + std::to_string(delta) + " steps (at most 4e15)";
          return false;
        }
        field(r, i) = from_steps(before + delta, i);
      }
    }
  }
  if ((flags & kTool) != 0) {
    read_tool(in, r);
    out.tip_check = tip_check(r.virtual_tip_mm);
  } else {
    out.tip_check = in.u32();
    out.tool_recorded = false;
  }
  if ((flags & kTouched) != 0) {
    const std::uint64_t grew = in.varint();
    if (!in.overrun() && (grew == 0 || grew > std::numeric_limits<std::uint32_t>::max() - p.touched_triangles)) {
      error = "a cycle's touched set growing by " + std::to_string(grew) + " from " + std::to_string(p.touched_triangles) +
              " (expected more than 0, to at most 2^32 - 1)";
      return false;
    }
    r.touched_triangles = p.touched_triangles + static_cast<std::uint32_t>(grew);
  }
  const std::uint8_t reason = (more & kSafe) != 0 ? in.u8() : static_cast<std::uint8_t>(p.safe_reason);
  r.status_bits = (more & kStatus) != 0 ? in.u16() : p.status_bits;
  const std::uint8_t status = (more & kRead) != 0 ? in.u8() : static_cast<std::uint8_t>(p.read_status);
  const std::uint8_t read_reason = (more & kRead) != 0 ? in.u8() : static_cast<std::uint8_t>(p.read_reason);
  if ((more & kMaxima) != 0) {
    r.max_force_n = in.f64();
    r.max_offset_mm = in.f64();
  }
  if (in.overrun()) {
    error = "a cycle cut short (or a number in it longer than 10 bytes)";
    return false;
  }
  if (!control::is_safe_reason_byte(reason) || !valid_read(status, read_reason)) {
    error = "a cycle's safe reason " + std::to_string(reason) + ", read status " + std::to_string(status) +
            " or read reason " + std::to_string(read_reason) + " is out of range";
    return false;
  }
  r.safe_reason = static_cast<control::SafeReason>(reason);
  r.read_status = static_cast<hal::ReadStatus>(status);
  r.read_reason = static_cast<hal::HapticFault>(read_reason);
  out.maxima_recorded = true;
  previous_step_ns_ = step_ns;
  previous_ = r;
  if (!out.tool_recorded) {
    constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
    for (double& v : r.virtual_tip_mm) {
      v = kUnknown;
    }
    for (float& v : r.force_n) {
      v = std::numeric_limits<float>::quiet_NaN();
    }
  }
  return true;
}

}  // namespace stencil::journal
