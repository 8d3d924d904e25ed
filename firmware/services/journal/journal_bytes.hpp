// Little-endian encoding of the journal's numbers and of a cycle record, shared by the writer and
// the reader so the two cannot drift apart.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/machine_record.hpp"

namespace stencil::journal {

class ByteWriter {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void u16(std::uint16_t v) { little(v, 2); }
  void u32(std::uint32_t v) { little(v, 4); }
  void u64(std::uint64_t v) { little(v, 8); }
  void i64(std::int64_t v) { little(static_cast<std::uint64_t>(v), 8); }
  void i32(std::int32_t v) { little(static_cast<std::uint32_t>(v), 4); }
  void f32(float v) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    little(bits, 4);
  }
  void f64(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    little(bits, 8);
  }
  // LEB128: seven bits a byte, low first, the top bit set while more follow (1 to 10 bytes).
  void varint(std::uint64_t v) {
    while (v >= 0x80U) {
      bytes_.push_back(static_cast<std::uint8_t>(v | 0x80U));
      v >>= 7U;
    }
    bytes_.push_back(static_cast<std::uint8_t>(v));
  }
  // A signed number as a varint, small either side of zero: 0, -1, 1, -2 ... as 0, 1, 2, 3 ...
  void zigzag(std::int64_t v) {
    varint((static_cast<std::uint64_t>(v) << 1U) ^ static_cast<std::uint64_t>(v >> 63));
  }
  void bytes(const std::uint8_t* data, std::size_t n) { bytes_.insert(bytes_.end(), data, data + n); }
  [[nodiscard]] const std::uint8_t* data() const { return bytes_.data(); }
  [[nodiscard]] std::size_t size() const { return bytes_.size(); }
  void clear() { bytes_.clear(); }

 private:
  void little(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) {
      bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
  }
  std::vector<std::uint8_t> bytes_;
};

// Reads numbers off a span; reading past its end gives zeros and sets overrun() (the caller has
// checked the length first, so this only guards against its own mistakes).
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(little(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(little(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(little(4)); }
  std::uint64_t u64() { return little(8); }
  std::int64_t i64() { return static_cast<std::int64_t>(little(8)); }
  std::int32_t i32() { return static_cast<std::int32_t>(static_cast<std::uint32_t>(little(4))); }
  float f32() {
    const auto bits = static_cast<std::uint32_t>(little(4));
    float v = 0.0F;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  double f64() {
    const std::uint64_t bits = little(8);
    double v = 0.0;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  // A varint as ByteWriter::varint writes it; more than 10 bytes, or a tenth byte over 1, is an
  // overrun (no writer makes one).
  std::uint64_t varint() {
    std::uint64_t v = 0;
    for (unsigned shift = 0; shift < 64; shift += 7) {
      const std::uint8_t byte = u8();
      if (overrun_ || (shift == 63 && byte > 1)) {
        overrun_ = true;
        return 0;
      }
      v |= static_cast<std::uint64_t>(byte & 0x7FU) << shift;
      if ((byte & 0x80U) == 0) {
        return v;
      }
    }
    overrun_ = true;
    return 0;
  }
  std::int64_t zigzag() {
    const std::uint64_t v = varint();
    return static_cast<std::int64_t>(v >> 1U) ^ -static_cast<std::int64_t>(v & 1U);
  }
  [[nodiscard]] std::size_t at() const { return at_; }
  [[nodiscard]] std::size_t left() const { return size_ - at_; }
  [[nodiscard]] const std::uint8_t* here() const { return data_ + at_; }
  void skip(std::size_t n) { at_ = n <= left() ? at_ + n : (overrun_ = true, size_); }
  [[nodiscard]] bool overrun() const { return overrun_; }

 private:
  std::uint64_t little(int n) {
    if (left() < static_cast<std::size_t>(n)) {
      overrun_ = true;
      at_ = size_;
      return 0;
    }
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) {
      v |= static_cast<std::uint64_t>(data_[at_ + static_cast<std::size_t>(i)]) << (8 * i);
    }
    at_ += static_cast<std::size_t>(n);
    return v;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
  bool overrun_ = false;
};

inline void encode_cycle(const control::JournalRecord& r, ByteWriter& out) {
  out.u64(r.cycle);
  out.i64(r.time_ns);
  for (const double v : r.device_mm) {
    out.f64(v);
  }
  for (const double v : r.angles_rad) {
    out.f64(v);
  }
  out.u32(r.sample_counter);
  out.u8(r.fresh ? 1 : 0);
  for (const double v : r.virtual_tip_mm) {
    out.f64(v);
  }
  out.u8(static_cast<std::uint8_t>(r.safe_reason));
  out.u32(r.touched_triangles);
  for (const float v : r.force_n) {
    out.f32(v);
  }
  out.u16(r.status_bits);
  out.u8(static_cast<std::uint8_t>(r.read_status));
  out.u8(static_cast<std::uint8_t>(r.read_reason));
}

inline void encode_machine_command(const control::MachineCommandRecord& r, ByteWriter& out) {
  out.u64(r.update);
  out.i64(r.time_ns);
  for (const std::int32_t v : r.motor_target) {
    out.i32(v);
  }
  for (const std::uint8_t v : r.order) {
    out.u8(v);
  }
  for (const double v : r.target_tip_mm) {
    out.f64(v);
  }
}

inline void encode_command(const control::CommandEvent& e, ByteWriter& out) {
  out.u64(e.cycle);
  out.i64(e.time_ns);
  out.u64(e.queued_after_cycle);
  out.u8(static_cast<std::uint8_t>(e.kind));
  out.u8(static_cast<std::uint8_t>(e.source));
  out.u8(static_cast<std::uint8_t>(e.outcome));
  out.f64(e.asked);
  out.f64(e.applied);
}

}  // namespace stencil::journal
