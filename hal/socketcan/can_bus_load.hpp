// How long a classic CAN frame is on the wire, and the load the haptic frame set puts on a bus of a
// given bitrate: the check the link makes when it is opened (a bus too slow for a period's frames is
// refused), and the wire time of the simulated bus. Pure and constexpr; real-time core.
#pragma once

#include <linux/can.h>

#include <cstdint>
#include <limits>

#include "hal/clock.hpp"
#include "hal/socketcan/can_frame_layout.hpp"

namespace stencil::hal::socketcan {

// A classic data frame with an 11-bit identifier and n data bytes, bit by bit (ISO 11898-1):
//
//   start of frame 1, identifier 11, RTR 1, IDE 1, r0 1, DLC 4, data 8n, CRC 15    34 + 8n, stuffed
//   CRC delimiter 1, ACK slot 1, ACK delimiter 1, end of frame 7                    10, fixed form
//   intermission 3 (the interframe space: no frame may start sooner)                3
//
// 47 + 8n bits with no stuff bit: 111 for our 8 bytes, intermission included. The sender adds a stuff
// bit after every 5 equal bits of the stuffed part; since a stuff bit starts the next run, there is at
// most one per 4 bits after the first: (34 + 8n - 1) / 4 more, 24 for 8 bytes, 135 bits in all at worst
// (Davis, Burns, Bril and Lukkien, "Controller Area Network (CAN) schedulability analysis: refuted,
// revisited and revised", Real-Time Systems 35, 2007, eq. 1).
[[nodiscard]] constexpr int classic_frame_bits_unstuffed(int data_bytes) { return 47 + 8 * data_bytes; }
[[nodiscard]] constexpr int classic_frame_bits_worst_case(int data_bytes) {
  return classic_frame_bits_unstuffed(data_bytes) + (34 + 8 * data_bytes - 1) / 4;
}

namespace detail {

// The stuffed part of a frame as it is sent, bit by bit: counts the stuff bits and computes the CRC.
struct StuffedBits {
  int stuff_bits = 0;
  int run_length = 0;
  bool last_bit = false;
  std::uint16_t crc = 0;  // CRC-15, polynomial 0x4599, over the bits before the CRC field

  constexpr void put(bool bit) {
    if (run_length == 5) {  // five equal bits went out: the complement goes next, and starts a run
      ++stuff_bits;
      last_bit = !last_bit;
      run_length = 1;
    }
    if (run_length > 0 && bit == last_bit) {
      ++run_length;
    } else {
      last_bit = bit;
      run_length = 1;
    }
  }
  constexpr void put_with_crc(bool bit) {
    const bool feedback = bit != (((crc >> 14U) & 1U) != 0U);
    crc = static_cast<std::uint16_t>((static_cast<std::uint32_t>(crc) << 1U) & 0x7FFFU);
    if (feedback) crc = static_cast<std::uint16_t>(static_cast<std::uint32_t>(crc) ^ 0x4599U);
    put(bit);
  }
  constexpr void put_field_with_crc(std::uint32_t value, int bits) {
    for (int bit = bits - 1; bit >= 0; --bit) put_with_crc(((value >> static_cast<unsigned>(bit)) & 1U) != 0U);
  }
};

}  // namespace detail

// This frame's own length on the wire in bits, its stuff bits and the intermission included: between
// classic_frame_bits_unstuffed(len) and classic_frame_bits_worst_case(len). Taken as a standard data
// frame (the identifier's low 11 bits, at most 8 data bytes): the only kind the haptic bus carries.
[[nodiscard]] constexpr int classic_frame_bits(const can_frame& frame) {
  const int data_bytes = frame.len > CAN_MAX_DLEN ? CAN_MAX_DLEN : frame.len;
  detail::StuffedBits wire;
  wire.put_with_crc(false);                                  // start of frame (dominant)
  wire.put_field_with_crc(frame.can_id & CAN_SFF_MASK, 11);  // identifier
  wire.put_field_with_crc(0, 3);                             // RTR, IDE, r0: a standard data frame
  wire.put_field_with_crc(static_cast<std::uint32_t>(data_bytes), 4);
  for (int byte = 0; byte < data_bytes; ++byte) wire.put_field_with_crc(frame.data[byte], 8);
  const std::uint16_t crc = wire.crc;
  for (int bit = 14; bit >= 0; --bit) wire.put(((crc >> static_cast<unsigned>(bit)) & 1U) != 0U);
  if (wire.run_length == 5) ++wire.stuff_bits;  // five equal bits ending the CRC are stuffed too
  return classic_frame_bits_unstuffed(data_bytes) + wire.stuff_bits;
}

// The frames every period: the device's PoseA, PoseB and Status, the host's Force and Torque.
inline constexpr int kHapticFramesPerPeriod = kDeviceFramesPerPeriod + kHostFramesPerPeriod;

// What a frame set needs from a bus, and whether a bitrate gives it.
struct BusLoad {
  std::uint64_t worst_case_bits_per_period;  // every frame with its most stuff bits
  std::uint64_t unstuffed_bits_per_period;   // with none
  std::uint64_t bits_available_per_period;   // what the bitrate carries in a period
  std::uint64_t bitrate_needed_bps;          // the slowest bitrate that carries the worst case in a period
  double worst_case_load;                    // worst-case bits / available bits: above 1 does not fit
  double unstuffed_load;
  bool fits;  // the worst case fits in the period: the frames can never pile up from one period to the next
};

// `frames_per_period` frames of `data_bytes` each, every `period_ns`, on a bus of `bitrate_bps`.
[[nodiscard]] constexpr BusLoad bus_load(int frames_per_period, int data_bytes, MonotonicNs period_ns,
                                         std::uint64_t bitrate_bps) {
  constexpr std::uint64_t kNsPerS = 1'000'000'000;
  const auto frames = static_cast<std::uint64_t>(frames_per_period);
  const auto period = static_cast<std::uint64_t>(period_ns);
  BusLoad load{};
  load.worst_case_bits_per_period = frames * static_cast<std::uint64_t>(classic_frame_bits_worst_case(data_bytes));
  load.unstuffed_bits_per_period = frames * static_cast<std::uint64_t>(classic_frame_bits_unstuffed(data_bytes));
  load.bits_available_per_period = bitrate_bps * period / kNsPerS;
  load.bitrate_needed_bps = (load.worst_case_bits_per_period * kNsPerS + period - 1) / period;
  const double bits_per_period_at_bitrate =
      static_cast<double>(bitrate_bps) * static_cast<double>(period) / static_cast<double>(kNsPerS);
  load.worst_case_load = bitrate_bps == 0 ? std::numeric_limits<double>::infinity()
                                          : static_cast<double>(load.worst_case_bits_per_period) / bits_per_period_at_bitrate;
  load.unstuffed_load = bitrate_bps == 0 ? std::numeric_limits<double>::infinity()
                                         : static_cast<double>(load.unstuffed_bits_per_period) / bits_per_period_at_bitrate;
  load.fits = load.worst_case_bits_per_period * kNsPerS <= bitrate_bps * period;
  return load;
}

// The haptic frame set (can_frame_layout.hpp) on a bus of `bitrate_bps`: 5 frames of 8 bytes a
// millisecond, 555 to 675 bits: 675 kbit/s needed; 500 kbit/s is 111-135 % loaded, 1 Mbit/s 55.5-67.5 %.
[[nodiscard]] constexpr BusLoad haptic_bus_load(std::uint64_t bitrate_bps) {
  return bus_load(kHapticFramesPerPeriod, kFrameBytes, kFramePeriodNs, bitrate_bps);
}

static_assert(classic_frame_bits_unstuffed(8) == 111 && classic_frame_bits_worst_case(8) == 135);
static_assert(haptic_bus_load(675'000).fits && !haptic_bus_load(500'000).fits);

}  // namespace stencil::hal::socketcan
