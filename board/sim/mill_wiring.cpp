// The simulated machine's far side and the driver's end, set up as the rig's are.
#include "board/sim/mill_wiring.hpp"

#include "board/sim/sim_facts.hpp"

namespace stencil::board::sim {
MillWiring::MillWiring(const SimJob& job, bool realtime)
    : mill_{mill_config(job.rig.mill_truth)},
      epoch_ns_(realtime ? hal::posix_clock::monotonic_now_ns() : 0),
      fake_{mill_, job.rig.mill_truth.mmc4s, epoch_ns_},
      relay_ns_(job.rig.mill_truth.watchdog_relay_timeout_ns),
      machined_{*job.part, job.stock, true_frames(job.rig),
                [this] { return static_cast<double>(fake_.chip().now_ns() - epoch_ns_) / 1e9; }} {
  // Virtual time only: it gives the fake's bytes their wire time and its commands the chip's time,
  // which in real time the fake cannot know (a pty merges the driver's writes).
  if (!realtime) {
    fast_clock_.emplace(fake_, 0, job.rig.facts.serial_baud);
  }
  fake_.board().set_channel_latching(stencil::sim::cy545::ChannelLatching::Address);
  fake_.chip().set_command_time_ns(0);  // see link_config's command_settle_ns
  // The rig's hardware watchdog relay on the heartbeat output (Mmc4sWiring::heartbeat_output).
  fake_.board().arm_watchdog_relay(job.rig.mill_truth.mmc4s.heartbeat_output, relay_ns_, epoch_ns_);
  machined_.set_trace(job.trace);
  machined_.set_allowance(job.rig.facts.machine_standoff_mm);  // the controller's standoff: stock it means to leave
  mill_.set_motion_observer(&machined_);
  char port_error[256] = {};
  if (!port_.open(fake_.slave_path().c_str(), job.rig.facts.serial_baud, port_error)) {
    error_ = std::string("the fake CY545's pty: ") + port_error;
    return;
  }
  link_ = std::make_unique<hal::cy545::Cy545Link>(port_, clock(), sim::link_config(realtime, job.rig.facts));  // the rig's, but (sim_facts.hpp)
}

MillWiring::~MillWiring() {
  runner_.reset();
  mill_.set_motion_observer(nullptr);
}

void MillWiring::start_answering() { runner_ = std::make_unique<stencil::sim::cy545::FakeCy545Runner>(fake_); }

void MillWiring::stop_answering() { runner_.reset(); }

void MillWiring::arm() {
  with_the_fake_still([this] {
    machined_.arm({mill_.axis_position_steps(stencil::sim::Axis::x), mill_.axis_position_steps(stencil::sim::Axis::y),
                   mill_.axis_position_steps(stencil::sim::Axis::z)});
  });
}

void MillWiring::after_machine_update() {
  with_the_fake_still([this] { machined_.flush(); });
}

void MillWiring::leave(SimResult& result, bool stop_confirmed, hal::MonotonicNs now_ns) {
  result.machine_stop_confirmed = stop_confirmed;
  result.mill_spindle_on_after_stop = mill_.spindle_on();
  result.mill_drivers_on_after_stop = mill_.drivers_enabled();
  fake_.board().advance_to(now_ns + relay_ns_ + 1'000'000);
  result.mill_relay_dropped_power = !fake_.board().watchdog_relay_closed() &&
                                    (result.mill_spindle_on_after_stop || result.mill_drivers_on_after_stop);
  result.mill_on_after_relay = mill_.spindle_on() || mill_.drivers_enabled();
}

}  // namespace stencil::board::sim
