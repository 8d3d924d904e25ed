// HapticDevice: the 5-DOF force-feedback handle as the 1 kHz cycle sees it (pose in, force out, a
// heartbeat both ways), with the plain-data sample, command, status and counter types it exchanges.
#pragma once

#include <cstdint>

#include "hal/clock.hpp"

namespace stencil::hal {

// Bits of HapticSample::status_bits, set by the device.
namespace haptic_status {
inline constexpr std::uint32_t kForceApplied = 1U << 0;         // the device is driving the commanded force
inline constexpr std::uint32_t kHostWatchdogTripped = 1U << 1;  // host heartbeat froze: the device zeroed its force
inline constexpr std::uint32_t kCommandRejected = 1U << 2;      // the last command was refused (out of range, torn)
inline constexpr std::uint32_t kDeviceFault = 1U << 3;          // the device's own fault (amplifier, encoder)
}  // namespace haptic_status

// Each link's expected delay from the cycle's command to the device's motors (s), estimated, not
// measured on a rig: the passivity observer and the speed penalty's velocity predictor weigh the
// force by it. PIO: the device's own 1 kHz loop reads the window at a phase of its own, on average
// half a period later. CAN: the two command frames (0x100, 0x101: 8 data bytes, about 130 bits each
// with stuffing) take 0.26 ms at 1 Mbit/s, after the device's three pose frames of the same period
// (0.4 ms): 0.7 ms (hal/socketcan/can_bus_load.hpp counts the bits).
inline constexpr double kPioCommandDelayS = 0.5e-3;
inline constexpr double kCanCommandDelayS = 0.7e-3;

// One pose sample, in device coordinates (origin at the centre of the device's reach).
struct HapticSample {
  double position_mm[3];         // x y z
  double angles_rad[2];          // the two sensed rotations of the handle (roll about its axis is not sensed)
  std::uint32_t sample_counter;  // moves by one per sample the device writes (about 1 kHz); wraps
  std::uint32_t status_bits;     // haptic_status::*
  std::uint32_t device_heartbeat;  // moves while the device's controller runs; frozen = disconnected
};

// One force command. The backend clamps and converts; the caller gives physical units.
struct HapticCommand {
  double force_n[3];            // x y z, device coordinates; clamped in magnitude to the board limit
  double torque_nmm[2];         // about the two sensed rotation axes; clamped in magnitude
  std::uint32_t cycle_counter;  // the caller's cycle number, echoed to the device for diagnosis
  bool enable;                  // false: the device drives no force whatever the numbers say
};

// What the backend accepts: positions and angles beyond these are refused, forces and torques are
// clamped to them (in magnitude) before they leave the host. Each board passes its device's (the
// Sherline rig's: board/sherline_suzuki/rig_facts.hpp).
struct HapticRange {
  double position_limit_mm[3];   // |position - centre| per axis: half the reach plus a margin
  double angle_limit_rad;        // |angle|, both angles
  double force_limit_n;          // the board's force limit
  double torque_limit_nmm;       // magnitude of the two-component torque
  double position_centre_mm[3];  // the middle of the reach in device coordinates
};

enum class ReadStatus : std::uint8_t {
  Fresh,     // a new sample (its counter moved) was accepted into `out`
  Stale,     // nothing new since the last read: `out` is untouched; normal now and then, not a hang
  Rejected,  // something new arrived but was refused (see reason): `out` is untouched
  Fault,     // the link is down (see reason): `out` is untouched
};

enum class WriteStatus : std::uint8_t {
  Written,   // sent as given
  Clamped,   // sent with force and/or torque clamped to the range
  Rejected,  // not finite: zero force with enable off was sent in its place (the heartbeat still beats)
  Fault,     // could not be sent (see reason)
  Held,      // enable on was asked, but the device has not confirmed that it is armed (its host watchdog
             // is clear after an enable off of this host's), or a HostWatchdogTripped has not been
             // cleared: zero force with enable off was sent in its place. Not a fault.
};

// Why a read or write was not Fresh / Written. Also the value of the error latch.
enum class HapticFault : std::uint8_t {
  None,
  NotOpen,                // no window / socket behind the backend
  SampleBusy,             // the device was mid-write on every attempt of the bounded retry (torn read)
  SampleOutOfRange,       // position or angle beyond the range, or beyond what the wire can carry
  SampleNotFinite,        // a NaN or infinity in the position or angles (an in-process device; no wire carries one)
  BadFrame,               // wrong length / DLC, unknown ID, halves that disagree (CAN)
  CommandNotFinite,       // a NaN or infinity in the command
  DeviceHeartbeatLost,    // the device heartbeat did not move for the watchdog time: disconnected
  TransportError,         // the socket or window reported an error
  TransportFull,          // the socket would block: the command was dropped
  HostWatchdogTripped,    // the device's host watchdog tripped while this host ran (the host stalled
                          // past the device's watchdog time): the device zeroed its force
};

enum class HapticLinkState : std::uint8_t {
  Closed,            // nothing behind the backend
  WaitingForDevice,  // open, no sample yet
  Connected,         // the device heartbeat moves
  Disconnected,      // the device heartbeat froze for longer than the watchdog time
};

struct [[nodiscard]] ReadResult {
  ReadStatus status;
  HapticFault reason;  // None when Fresh or Stale
};

struct [[nodiscard]] WriteResult {
  WriteStatus status;
  HapticFault reason;  // None when Written, Clamped or Held
};

// Rejected input, counted since construction. Never reset by the backend.
struct HapticCounters {
  std::uint64_t samples_accepted;
  std::uint64_t stale_reads;
  std::uint64_t torn_read_retries;     // read attempts that met a write in progress and tried again
  std::uint64_t busy_reads;            // reads that gave up after the retry bound
  std::uint64_t samples_out_of_range;
  std::uint64_t bad_frames;            // CAN: every rejected frame, whatever the kind
  std::uint64_t commands_clamped;
  std::uint64_t commands_rejected;     // not finite
  std::uint64_t transport_errors;      // failed or would-block sends and receives
};

// The device as the cycle sees it. Every method here is real-time safe (no allocation, lock, throw,
// blocking call, or loop without a fixed bound); opening the window or socket is the backend's own
// init-time business, before the cycle starts.
class HapticDevice {
 public:
  HapticDevice() = default;
  HapticDevice(const HapticDevice&) = delete;
  HapticDevice& operator=(const HapticDevice&) = delete;

  // The latest sample, if a new one arrived since the last call. Never blocks: a device that stopped
  // writing gives Stale (the counter did not move), and after the watchdog time without its heartbeat
  // moving, Fault / DeviceHeartbeatLost. `now_ns` drives that watchdog (monotonic). `out` is written
  // only when the result is Fresh; it carries the device's status bits as the device set them.
  // A device that reports its host watchdog tripped after it had confirmed it was armed for this
  // backend (this host stalled) gives Fault / HostWatchdogTripped, once; one found tripped at the
  // start (an earlier host's run) is re-armed by write_command, not reported.
  virtual ReadResult read_sample(MonotonicNs now_ns, HapticSample& out) = 0;

  // Sends one command and beats the host heartbeat (every call, whatever the command, unless the
  // result is Fault). Forces are clamped to the range; a command that is not finite sends zero force
  // with enable off instead. A device with a host watchdog drives nothing after a trip until it has
  // seen enable off and then enable on; the backend therefore sends enable off (Held) until the device
  // confirms it is armed, at the start and after a trip, and after a trip until clear_fault().
  virtual WriteResult write_command(const HapticCommand& command) = 0;

  [[nodiscard]] virtual HapticLinkState link_state() const = 0;

  // The reason of the first read or write that returned Fault since construction or the last
  // clear_fault(); None when there was none. Rejected input is counted, not latched. The cycle stops
  // commanding force once it is set.
  [[nodiscard]] virtual HapticFault latched_fault() const = 0;
  virtual void clear_fault() = 0;

  [[nodiscard]] virtual HapticCounters counters() const = 0;

 protected:
  // Not virtual, and not public: backends are created by the board (statically) and never deleted
  // through this interface; a virtual destructor would pull operator delete into the real-time core.
  ~HapticDevice() = default;
};

}  // namespace stencil::hal
