// SimulatedCanBus: the classic CAN bus between the host and the simulated haptic device, in process and
// on a clock the caller moves (a VirtualClock in tests and fast runs: the same traffic gives the same
// timing every run), as unkind as the real bus. Not real-time code.
//
// What it models, and why each matters to the haptic link:
// - Bandwidth: a frame occupies the wire for its exact length in bits (its own stuff bits and the
//   3-bit intermission counted, hal/socketcan/can_bus_load.hpp) at the configured bitrate; it reaches
//   the other node when its last bit has. A period's frames that do not fit in the period arrive late.
// - Arbitration: when the bus goes idle, of the frames waiting at the head of each node's transmit
//   queue the one with the lowest identifier goes first (the host's commands, 0x100/0x101, beat the
//   device's poses, 0x180-0x182: on an overloaded bus the poses are the ones that wait).
// - Each node's transmit queue is bounded (the interface's txqueuelen): a send into a full one is
//   refused (WouldBlock, as the kernel's ENOBUFS) and counted.
// - Each node's receive queue is bounded (the socket's receive buffer): a frame arriving at a full one
//   is dropped and counted. As in the kernel, it is the newest frame that is lost, never a waiting one.
// - Error frames: the node's own driver reports them into its receive queue (they never cross the
//   wire). A node can go bus-off: the frame it had on the wire is lost, it sends and receives nothing
//   and reports CAN_ERR_BUSOFF; restart() reports CAN_ERR_RESTARTED and it carries on.
//
// host() and device() are the two nodes' CanChannels: a SocketCanHapticDevice on one, a CanDeviceLink
// on the other, in place of a socket pair (which delivers at once, whatever the load).
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <deque>

#include "hal/clock.hpp"
#include "hal/socketcan/can_channel.hpp"
#include "hal/socketcan/can_frame_layout.hpp"

namespace stencil::sim {

enum class CanNode : std::uint8_t { Host, Device };

struct CanBusConfig {
  std::uint64_t bitrate_bps = 1'000'000;  // the rig's bus (not 0); 500'000 cannot carry the haptic frames
  // Each node's socket receive buffer, in frames: a CAN_RAW socket's default buffer (rmem_default,
  // 212992 bytes) holds about 277 frames at about 768 bytes of kernel memory each (x86-64). The host
  // backend's first read assumes a buffer of well over hal::socketcan::kMaxFramesPerRead frames.
  std::size_t receive_queue_frames = 277;
  std::size_t transmit_queue_frames = 10;  // a CAN interface's default txqueuelen
  // A frame delivered more than this after it was sent is counted late (one haptic period).
  hal::MonotonicNs period_ns = hal::socketcan::kFramePeriodNs;
};

// What happened at one node.
struct CanNodeCounters {
  std::uint64_t transmit_refused;  // sends refused: its transmit queue was full
  std::uint64_t receive_dropped;   // frames that reached it with its receive queue full: dropped
  std::uint64_t lost_to_bus_off;   // its frame on the wire when it went bus-off, and frames sent to it meanwhile
  std::uint64_t error_frames;      // error frames its driver reported (into its receive queue, or dropped)
};

struct CanBusCounters {
  std::uint64_t frames_carried;      // frames whose last bit crossed the wire
  std::uint64_t bits_carried;        // their length in bits, stuff bits and intermission included
  std::uint64_t frames_late;         // delivered more than a period after they were sent
  hal::MonotonicNs max_latency_ns;   // sent (queued) to delivered, the longest
  CanNodeCounters host;
  CanNodeCounters device;
};

class SimulatedCanBus {
 public:
  // `clock` must outlive this object; the bus moves only as far as it says. Throws
  // std::invalid_argument for a bitrate of 0.
  SimulatedCanBus(const hal::Clock& clock, const CanBusConfig& config);
  SimulatedCanBus(const SimulatedCanBus&) = delete;
  SimulatedCanBus& operator=(const SimulatedCanBus&) = delete;

  [[nodiscard]] hal::socketcan::CanChannel& host() { return host_end_; }
  [[nodiscard]] hal::socketcan::CanChannel& device() { return device_end_; }

  // The node's driver reports this error frame (CAN_ERR_FLAG set) into its own receive queue, now.
  void report_error(CanNode node, const can_frame& error_frame);
  // The node's controller goes bus-off now (see above); restart() brings it back.
  void go_bus_off(CanNode node);
  void restart(CanNode node);
  [[nodiscard]] bool bus_off(CanNode node) const;

  // Carries the bus up to the clock's now: every send and receive does this first.
  void update();

  // As of now (updates first).
  [[nodiscard]] const CanBusCounters& counters();
  [[nodiscard]] const CanBusConfig& config() const { return config_; }

 private:
  class End final : public hal::socketcan::CanChannel {
   public:
    End(SimulatedCanBus& bus, CanNode node) : bus_(bus), node_(node) {}
    [[nodiscard]] hal::socketcan::TransferStatus receive(can_frame& frame) override { return bus_.receive(node_, frame); }
    [[nodiscard]] hal::socketcan::TransferStatus send(const can_frame& frame) override { return bus_.send(node_, frame); }

   private:
    SimulatedCanBus& bus_;
    CanNode node_;
  };

  struct Queued {
    can_frame frame;
    hal::MonotonicNs queued_ns;
  };

  struct Node {
    std::deque<Queued> transmit;
    std::deque<can_frame> receive;
    bool bus_off = false;
  };

  hal::socketcan::TransferStatus receive(CanNode node, can_frame& frame);
  hal::socketcan::TransferStatus send(CanNode node, const can_frame& frame);
  void deliver(CanNode to, const can_frame& frame);
  [[nodiscard]] Node& node(CanNode which) { return nodes_[static_cast<int>(which)]; }
  [[nodiscard]] CanNodeCounters& counters_of(CanNode which) {
    return which == CanNode::Host ? counters_.host : counters_.device;
  }

  const hal::Clock& clock_;
  CanBusConfig config_;
  Node nodes_[2];
  End host_end_{*this, CanNode::Host};
  End device_end_{*this, CanNode::Device};
  // The frame on the wire, if any.
  bool wire_busy_ = false;
  Queued on_wire_{};
  CanNode on_wire_from_ = CanNode::Host;
  hal::MonotonicNs wire_done_ns_ = 0;
  hal::MonotonicNs bus_idle_since_ns_;
  CanBusCounters counters_{};
};

}  // namespace stencil::sim
