// The simulated CAN bus: frames on the wire for their length at the bitrate, arbitration by
// identifier, bounded queues that refuse or drop and count, error frames and bus-off.
#include "sim/haptic_device/simulated_can_bus.hpp"

#include <linux/can/error.h>

#include <limits>
#include <stdexcept>

#include "hal/socketcan/can_bus_load.hpp"
#include "hal/socketcan/can_error_frames.hpp"

namespace stencil::sim {

namespace can = hal::socketcan;

namespace {

constexpr CanNode other(CanNode node) { return node == CanNode::Host ? CanNode::Device : CanNode::Host; }

}  // namespace

SimulatedCanBus::SimulatedCanBus(const hal::Clock& clock, const CanBusConfig& config)
    : clock_(clock), config_(config), bus_idle_since_ns_(std::numeric_limits<hal::MonotonicNs>::min()) {
  if (config_.bitrate_bps == 0) throw std::invalid_argument("SimulatedCanBus: a bitrate of 0 bit/s carries nothing");
}

void SimulatedCanBus::update() {
  const hal::MonotonicNs now = clock_.now_ns();
  for (;;) {
    if (wire_busy_) {
      if (wire_done_ns_ > now) return;
      wire_busy_ = false;
      bus_idle_since_ns_ = wire_done_ns_;
      const hal::MonotonicNs latency = wire_done_ns_ - on_wire_.queued_ns;
      ++counters_.frames_carried;
      counters_.bits_carried += static_cast<std::uint64_t>(can::classic_frame_bits(on_wire_.frame));
      if (latency > counters_.max_latency_ns) counters_.max_latency_ns = latency;
      if (latency > config_.period_ns) ++counters_.frames_late;
      deliver(other(on_wire_from_), on_wire_.frame);
    }
    // The next frame: when the bus is idle and something waits, of the frames waiting by then the one
    // with the lowest identifier (a bus-off node sends nothing).
    hal::MonotonicNs first_waiting = std::numeric_limits<hal::MonotonicNs>::max();
    for (const Node& candidate : nodes_) {
      if (!candidate.bus_off && !candidate.transmit.empty() && candidate.transmit.front().queued_ns < first_waiting) {
        first_waiting = candidate.transmit.front().queued_ns;
      }
    }
    if (first_waiting == std::numeric_limits<hal::MonotonicNs>::max()) return;
    const hal::MonotonicNs start = bus_idle_since_ns_ > first_waiting ? bus_idle_since_ns_ : first_waiting;
    if (start > now) return;
    CanNode winner = CanNode::Host;
    bool found = false;
    for (const CanNode candidate : {CanNode::Host, CanNode::Device}) {
      const Node& at = node(candidate);
      if (at.bus_off || at.transmit.empty() || at.transmit.front().queued_ns > start) continue;
      if (!found || (at.transmit.front().frame.can_id & CAN_SFF_MASK) <
                        (node(winner).transmit.front().frame.can_id & CAN_SFF_MASK)) {
        winner = candidate;
        found = true;
      }
    }
    Node& sender = node(winner);
    on_wire_ = sender.transmit.front();
    sender.transmit.pop_front();
    on_wire_from_ = winner;
    wire_busy_ = true;
    const auto bits = static_cast<std::uint64_t>(can::classic_frame_bits(on_wire_.frame));
    const std::uint64_t wire_ns = (bits * 1'000'000'000ULL + config_.bitrate_bps - 1) / config_.bitrate_bps;
    wire_done_ns_ = start + static_cast<hal::MonotonicNs>(wire_ns);
  }
}

void SimulatedCanBus::deliver(CanNode to, const can_frame& frame) {
  Node& receiver = node(to);
  if (receiver.bus_off) {
    ++counters_of(to).lost_to_bus_off;
    return;
  }
  if (receiver.receive.size() >= config_.receive_queue_frames) {
    ++counters_of(to).receive_dropped;  // the newest is lost: the waiting frames stay, as in the kernel
    return;
  }
  receiver.receive.push_back(frame);
}

can::TransferStatus SimulatedCanBus::receive(CanNode which, can_frame& frame) {
  update();
  Node& at = node(which);
  if (at.receive.empty()) return can::TransferStatus::WouldBlock;
  frame = at.receive.front();
  at.receive.pop_front();
  return can::TransferStatus::Done;
}

can::TransferStatus SimulatedCanBus::send(CanNode from, const can_frame& frame) {
  update();
  Node& sender = node(from);
  if (sender.transmit.size() >= config_.transmit_queue_frames) {
    ++counters_of(from).transmit_refused;
    return can::TransferStatus::WouldBlock;
  }
  sender.transmit.push_back({frame, clock_.now_ns()});
  update();  // an idle bus takes it at once
  return can::TransferStatus::Done;
}

void SimulatedCanBus::report_error(CanNode which, const can_frame& error_frame) {
  update();
  ++counters_of(which).error_frames;
  Node& at = node(which);
  if (at.receive.size() >= config_.receive_queue_frames) {
    ++counters_of(which).receive_dropped;
    return;
  }
  at.receive.push_back(error_frame);
}

void SimulatedCanBus::go_bus_off(CanNode which) {
  update();
  if (wire_busy_ && on_wire_from_ == which) {
    wire_busy_ = false;
    bus_idle_since_ns_ = clock_.now_ns();
    ++counters_of(which).lost_to_bus_off;
  }
  node(which).bus_off = true;
  report_error(which, can::make_error_frame(CAN_ERR_BUSOFF));
}

void SimulatedCanBus::restart(CanNode which) {
  update();
  node(which).bus_off = false;
  report_error(which, can::make_error_frame(CAN_ERR_RESTARTED));
  update();  // what it queued meanwhile may go now
}

bool SimulatedCanBus::bus_off(CanNode which) const { return nodes_[static_cast<int>(which)].bus_off; }

const CanBusCounters& SimulatedCanBus::counters() {
  update();
  return counters_;
}

}  // namespace stencil::sim
