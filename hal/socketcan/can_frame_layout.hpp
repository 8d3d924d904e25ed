// The CAN frames the haptic device and the host exchange (classic CAN, 11-bit IDs, 8-byte payloads):
// IDs, byte layouts, scales and the rules for pairing and refusing frames.
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <cstdint>

namespace stencil::hal::socketcan {

// Every frame is a standard (11-bit) data frame with exactly 8 data bytes (DLC 8). Multi-byte fields
// are little-endian two's complement. Byte 0 of every frame is a sequence counter (8 bits, wraps).
//
// Device -> host, once per device cycle (1 kHz), in this order:
//
//   0x180 PoseA    [0] counter  [1..3] x  int24 um      [4..6] y  int24 um      [7] reserved, 0
//   0x181 PoseB    [0] counter  [1..3] z  int24 um      [4..5] angle 0 int16    [6..7] angle 1 int16
//                                                         (angles in units of 100 urad)
//   0x182 Status   [0] counter  [1..2] status bits u16  [3..6] device heartbeat u32  [7] reserved, 0
//
//   A pose is the pair PoseA, PoseB carrying the same counter; PoseA comes first. A PoseB whose
//   counter differs from the waiting PoseA, or that comes with no PoseA waiting, is refused and so is
//   the PoseA: the pose is never applied. A PoseA that replaces a waiting PoseA refuses the old one.
//   The Status counter is the same as the pose's (information only; it is not paired).
//
// Host -> device, once per host cycle (1 kHz), in this order:
//
//   0x100 Force    [0] counter  [1..2] fx int16 mN  [3..4] fy int16 mN  [5..6] fz int16 mN
//                  [7] flags: bit 0 enable, other bits 0
//   0x101 Torque   [0] counter  [1..2] torque 0 int16  [3..4] torque 1 int16  (units of 10 mN.mm)
//                  [5..6] host heartbeat u16  [7] reserved, 0
//
//   A command is the pair Force, Torque with the same counter (the low 8 bits of the host's cycle
//   counter), paired like the pose. The host heartbeat moves by one with every command sent.
//
// Scales and why: 24-bit micrometres reach +-8.388 m (the device reaches +-0.25 m); 16-bit angles at
// 100 urad reach +-3.2767 rad (a half turn); 16-bit millinewtons reach +-32.7 N (the board limit is
// 5 N). Torque is carried in units of 10 mN.mm, not 1 mN.mm: 16 bits of mN.mm would stop at 32.8 N.mm,
// below the engine's 200 N.mm torque limit (5 N at a 40 mm lever); 10 mN.mm reach 327 N.mm.
//
// Refused frames (counted by kind, never applied): DLC other than 8; an ID not listed for the
// receiving side, an extended-ID or remote frame; a value out of range (a pose beyond the host's
// HapticRange, a force magnitude above 5000 mN or torque magnitude above 20000 units at the device);
// a reserved byte or flag bit that is not zero; halves that disagree or come unpaired.
//
// Watchdogs: the host treats a device heartbeat (Status) that has not moved for its watchdog time as
// a disconnect; the device zeroes its force when the host heartbeat has not moved for kHostWatchdogMs
// and keeps it zero until a command with enable off, then one with enable on (see
// ../pio_shared_memory/shared_window_layout.hpp: the same rule on both backends).

inline constexpr canid_t kPoseAId = 0x180;
inline constexpr canid_t kPoseBId = 0x181;
inline constexpr canid_t kStatusId = 0x182;
inline constexpr canid_t kForceId = 0x100;
inline constexpr canid_t kTorqueId = 0x101;

// The frame set of one period, each side's frames in the order it sends them: what the bus must
// carry every kFramePeriodNs (see can_bus_load.hpp), and what each side's socket receives.
inline constexpr canid_t kDeviceFrameIds[] = {kPoseAId, kPoseBId, kStatusId};
inline constexpr canid_t kHostFrameIds[] = {kForceId, kTorqueId};
inline constexpr int kDeviceFramesPerPeriod = static_cast<int>(sizeof kDeviceFrameIds / sizeof kDeviceFrameIds[0]);
inline constexpr int kHostFramesPerPeriod = static_cast<int>(sizeof kHostFrameIds / sizeof kHostFrameIds[0]);
inline constexpr std::int64_t kFramePeriodNs = 1'000'000;  // both sides send once per 1 kHz cycle

inline constexpr std::uint8_t kFrameBytes = 8;
inline constexpr std::int32_t kInt24Min = -(1 << 23);
inline constexpr std::int32_t kInt24Max = (1 << 23) - 1;
inline constexpr double kAngleRadPerUnit = 100e-6;
inline constexpr double kTorqueNmmPerUnit = 10e-3;
inline constexpr std::uint8_t kEnableFlag = 1U << 0;
inline constexpr std::int32_t kForceLimitMn = 5000;         // device side
inline constexpr std::int32_t kTorqueLimitUnits = 20000;    // device side: 200 N.mm
inline constexpr std::uint32_t kHostWatchdogMs = 20;        // device side

static_assert(sizeof(can_frame) == CAN_MTU);
static_assert(offsetof(can_frame, data) == 8);
static_assert(sizeof(can_frame::data) == kFrameBytes);

// The frames' fields as integers on the wire.
struct PoseWire {
  std::uint8_t counter;
  std::int32_t position_um[3];     // each within int24
  std::int16_t angles_100urad[2];
};

struct StatusWire {
  std::uint8_t counter;
  std::uint16_t status_bits;
  std::uint32_t device_heartbeat;
};

struct CommandWire {
  std::uint8_t counter;
  std::int16_t force_mn[3];
  std::int16_t torque_10mnmm[2];
  std::uint16_t host_heartbeat;
  bool enable;
};

}  // namespace stencil::hal::socketcan
