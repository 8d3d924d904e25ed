// The byte layout of the memory window that the PIO card's device controller and the host share,
// and the rules each side follows when it reads or writes it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace stencil::hal::pio_shared_memory {

// The window (on the rig a UIO device /dev/uioN, map 0; in tests a file or a memfd) holds three
// 64-byte blocks, each on its own cache line so the two writers never share one. All words are
// little-endian, naturally aligned, 32 bits: both sides access them as lock-free 32-bit atomics.
//
//   offset  block          written by  read by
//   0       WindowHeader   device      host (checked once, at open)
//   64      PoseBlock      device      host (every cycle)
//   128     CommandBlock   host        device (every device cycle)
//
// Seqlock (both blocks). The writer makes `sequence` odd (store, then a release fence), stores the
// fields, then makes `sequence` even again with a release store: sequence = 2 * writes. The reader
// loads `sequence` (acquire); if odd, a write is in progress; otherwise it loads the fields, fences
// (acquire) and loads `sequence` again: equal means the fields belong to one write. Readers retry at
// most kSeqlockAttempts times, then report the block busy; they never use a mixed block and never
// wait. sequence == 0 means the block was never written.
//
// Heartbeats. The device increments `device_heartbeat` with every pose it writes; the host increments
// `host_heartbeat` with every command it writes (whatever its content). Each side watches the other's:
//  - the host treats a device heartbeat that has not moved for its watchdog time (default 50 ms) as a
//    disconnect;
//  - the device (the real controller, and sim/haptic_device) zeroes its force when the host
//    heartbeat has not moved for kHostWatchdogMs, sets haptic_status::kHostWatchdogTripped, and keeps
//    the force at zero until the host has sent a command with enable off (re-arm) and then one with
//    enable on, so a dead or restarted host can never leave force on the handle. The trip outlives
//    the host: a host that starts finds the device as the last one left it, perhaps tripped.
//  - so the host sends enable off, whatever its caller asks, from its start (and again after a trip)
//    until it has read kHostWatchdogTripped clear in a pose the device wrote after reading that
//    enable off: two or more samples after the first pose the host read once it had written it. A
//    trip reported after that is the host's own stall (its caller hears it); one found at its start
//    is an earlier host's.
//
// Range rules. The host clamps force (magnitude) to the board's 5 N and torque to its limit before
// writing, and never writes a non-finite value (it sends zero with enable off instead). The device
// refuses a command whose force magnitude exceeds kForceLimitMn or whose torque magnitude exceeds
// kTorqueLimitMnmm (it drives zero and sets kCommandRejected). The host refuses a pose whose position
// or angles are beyond its HapticRange.

inline constexpr std::uint32_t kWindowMagic = 0x50415448U;  // the bytes "HTAP" in memory
inline constexpr std::uint32_t kLayoutVersion = 1;
inline constexpr std::size_t kWindowBytes = 192;
inline constexpr int kSeqlockAttempts = 64;  // reads of a block before it is reported busy
inline constexpr std::uint32_t kCommandEnableBit = 1U << 0;  // CommandBlock::flags
inline constexpr std::int32_t kForceLimitMn = 5000;          // the board's 5 N, device side
inline constexpr std::int32_t kTorqueLimitMnmm = 200000;     // 200 N·mm, device side
inline constexpr std::uint32_t kHostWatchdogMs = 20;         // device side: host heartbeat frozen this long

struct alignas(64) WindowHeader {
  std::uint32_t magic;           // kWindowMagic once the device has initialised the window
  std::uint32_t layout_version;  // kLayoutVersion
  std::uint32_t window_bytes;    // kWindowBytes
  std::uint32_t reserved[13];    // zero
};

struct alignas(64) PoseBlock {
  std::uint32_t sequence;          // seqlock, see above
  std::uint32_t sample_counter;    // +1 per pose written
  std::int32_t position_um[3];     // x y z, device coordinates, micrometres
  std::int32_t angles_urad[2];     // the two sensed rotations, microradians
  std::uint32_t status_bits;       // hal::haptic_status::*
  std::uint32_t device_heartbeat;  // +1 per pose written while the controller runs
  std::uint32_t reserved[7];       // zero
};

struct alignas(64) CommandBlock {
  std::uint32_t sequence;        // seqlock, see above
  std::uint32_t cycle_counter;   // the host's cycle number
  std::int32_t force_mn[3];      // x y z, millinewtons
  std::int32_t torque_mnmm[2];   // about the two sensed axes, millinewton-millimetres
  std::uint32_t flags;           // kCommandEnableBit; other bits zero
  std::uint32_t host_heartbeat;  // +1 per command written
  std::uint32_t reserved[7];     // zero
};

struct SharedWindow {
  WindowHeader header;
  PoseBlock pose;
  CommandBlock command;
};

static_assert(sizeof(WindowHeader) == 64);
static_assert(sizeof(PoseBlock) == 64);
static_assert(sizeof(CommandBlock) == 64);
static_assert(sizeof(SharedWindow) == kWindowBytes);
static_assert(offsetof(SharedWindow, header) == 0);
static_assert(offsetof(SharedWindow, pose) == 64);
static_assert(offsetof(SharedWindow, command) == 128);
static_assert(offsetof(PoseBlock, sequence) == 0);
static_assert(offsetof(PoseBlock, sample_counter) == 4);
static_assert(offsetof(PoseBlock, position_um) == 8);
static_assert(offsetof(PoseBlock, angles_urad) == 20);
static_assert(offsetof(PoseBlock, status_bits) == 28);
static_assert(offsetof(PoseBlock, device_heartbeat) == 32);
static_assert(offsetof(CommandBlock, sequence) == 0);
static_assert(offsetof(CommandBlock, cycle_counter) == 4);
static_assert(offsetof(CommandBlock, force_mn) == 8);
static_assert(offsetof(CommandBlock, torque_mnmm) == 20);
static_assert(offsetof(CommandBlock, flags) == 28);
static_assert(offsetof(CommandBlock, host_heartbeat) == 32);

// The fields of a block without its sequence word: what one seqlock read or write moves.
struct PoseWords {
  std::uint32_t sample_counter;
  std::int32_t position_um[3];
  std::int32_t angles_urad[2];
  std::uint32_t status_bits;
  std::uint32_t device_heartbeat;
};

struct CommandWords {
  std::uint32_t cycle_counter;
  std::int32_t force_mn[3];
  std::int32_t torque_mnmm[2];
  std::uint32_t flags;
  std::uint32_t host_heartbeat;
};

static_assert(sizeof(PoseWords) == offsetof(PoseBlock, reserved) - sizeof(std::uint32_t));
static_assert(sizeof(CommandWords) == offsetof(CommandBlock, reserved) - sizeof(std::uint32_t));

}  // namespace stencil::hal::pio_shared_memory
