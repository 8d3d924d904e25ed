// SocketCanHapticDevice: the host's side of the haptic CAN exchange (can_frame_layout.hpp) as a
// hal::HapticDevice, over any CanChannel. Real-time core: the codec and bounded, non-blocking frame
// moves only.
#pragma once

#include <cstdint>

#include "hal/haptic_device.hpp"
#include "hal/heartbeat_watchdog.hpp"
#include "hal/socketcan/can_channel.hpp"
#include "hal/socketcan/can_codec.hpp"
#include "hal/socketcan/can_error_frames.hpp"

namespace stencil::hal::socketcan {

inline constexpr MonotonicNs kDefaultDeviceWatchdogNs = 50'000'000;  // 50 missed status frames at 1 kHz
// Frames drained per read: 3 per device cycle, so about 10 ms of backlog; more waits for the next read.
inline constexpr int kMaxFramesPerRead = 32;
// Frames thrown away per read while a backlog found at the first read is discarded (below). A CAN_RAW
// socket's default receive buffer (rmem_default, 212992 bytes) holds about 277 frames (about 768
// bytes of kernel memory each on x86-64), so the first read, which looks at 33 and then discards up
// to this many more, empties it; at 1-2 us a non-blocking recv that read spends at most about half a
// period on it. A larger buffer takes more reads; the controller allows 5 periods without a fresh
// sample.
inline constexpr int kMaxFramesDiscardedPerRead = 256;

// What the CAN link saw beyond HapticCounters, since construction. Never reset.
struct CanLinkCounters {
  std::uint64_t error_frames;               // error frames from the controller's driver, faults or not
  std::uint64_t frames_discarded_at_start;  // the backlog of the link's unread time, thrown away (below)
};

// Stale frames at the start. The socket is opened at init and the cycle starts after homing, minutes
// later; meanwhile the device sends 3 frames a millisecond that nobody reads. Once the socket's receive
// buffer is full the kernel drops the *newest* frames, so what waits is the oldest: minutes old. The
// first read therefore looks at what waits: no more than one ordinary read takes (kMaxFramesPerRead,
// about 10 ms of frames, far less than the buffer holds) cannot have overflowed and is taken as any
// read takes it; more means the link sat unread, and every data frame waiting is discarded (at most
// kMaxFramesDiscardedPerRead per read, carried on at the next reads until the queue is empty), the
// reads say Stale, and the first pose is one the device sent after. Error frames in that backlog are
// not discarded: the link failed while nobody read it. This is done at the first read rather than by
// a call the board makes before starting the cycle because it then needs no caller and cannot be
// forgotten or made too early (homing between it and the cycle would leave a backlog again), and
// because every board, the simulation's included, gets it; it costs no fresh sample when the first
// read finds only the frames of the last few milliseconds.
class SocketCanHapticDevice final : public HapticDevice {
 public:
  // `channel` may be null (Closed). It must outlive this object. Init-time.
  SocketCanHapticDevice(CanChannel* channel, const HapticRange& range,
                        MonotonicNs device_watchdog_ns = kDefaultDeviceWatchdogNs);

  // Drains at most kMaxFramesPerRead waiting frames (never waits), pairs the pose halves, and gives
  // the newest complete pose. Fresh when a new pose arrived; Rejected / BadFrame or SampleOutOfRange
  // when frames arrived but none made a pose and some were refused; Stale when nothing new came (or a
  // stale backlog was discarded, above); Fault on a closed or failing channel, on an error frame that
  // stops the link (TransportError; bus_error() names it: bus-off, controller problem ...), or on a
  // device heartbeat (Status frame) frozen past the watchdog time. The read that meets an error frame
  // stops there: the frames behind it wait for the next read.
  ReadResult read_sample(MonotonicNs now_ns, HapticSample& out) override;

  // Sends the Force and Torque frames of one command (never waits). Fault / TransportFull when the
  // channel's queue is full (the command is dropped and counted), TransportError when it fails.
  WriteResult write_command(const HapticCommand& command) override;

  [[nodiscard]] HapticLinkState link_state() const override { return state_; }
  [[nodiscard]] HapticFault latched_fault() const override { return latched_fault_; }
  void clear_fault() override {
    latched_fault_ = HapticFault::None;
    bus_error_ = CanBusError::None;
  }
  [[nodiscard]] HapticCounters counters() const override;

  // What the first error frame that stopped the link since construction or the last clear_fault()
  // said (latched with latched_fault(), which is then TransportError); None when none did.
  [[nodiscard]] CanBusError bus_error() const { return bus_error_; }
  [[nodiscard]] const CanLinkCounters& can_counters() const { return can_counters_; }

  // Refused frames by kind (HapticCounters::bad_frames is their total).
  [[nodiscard]] const RejectionCounters& rejections() const { return assembler_.rejections(); }

 private:
  // What the frames of one read did.
  struct Drained {
    bool new_pose = false;
    bool status = false;                         // a Status frame was accepted
    FrameRejection refused = FrameRejection::None;
    HapticFault fault = HapticFault::None;       // not None: the read ends in Fault for this reason
  };

  ReadResult read_fault(HapticFault reason);
  WriteResult write_fault(HapticFault reason);
  // One receive's result into the assembler (or the error latch).
  void take(TransferStatus received, const can_frame& frame, Drained& drained);
  // The first read's look at what waits, and the discarding of a backlog (see the class comment).
  void drain_at_start(Drained& drained);
  void discard_backlog(Drained& drained);

  CanChannel* channel_;
  HapticRange range_;
  HostFrameAssembler assembler_;
  HeartbeatWatchdog device_watchdog_;
  HapticLinkState state_;
  HapticFault latched_fault_ = HapticFault::None;
  CanBusError bus_error_ = CanBusError::None;
  HapticCounters counters_{};
  CanLinkCounters can_counters_{};
  bool first_read_done_ = false;
  bool discarding_backlog_ = false;
  bool status_since_bus_error_ = true;  // Connected again only once a Status frame follows an error frame
  std::uint32_t sample_counter_ = 0;  // the 8-bit wire counter, extended
  bool seen_a_pose_ = false;
  std::uint16_t host_heartbeat_ = 0;
};

}  // namespace stencil::hal::socketcan
