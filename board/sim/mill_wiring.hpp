// The simulation's machine: the far side of the serial cable (the mill, its fake CY545 on a pty, the
// clock they follow, the ground truth of what is machined, the rig's watchdog relay) and this side's
// end of it (the serial port and the CY545 driver the rig runs).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "board/sim/sim_job.hpp"
#include "board/sim/sim_machine.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "hal/clock.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_clock.hpp"
#include "sim/cy545/fake_cy545_runner.hpp"
#include "sim/mill/machined_part.hpp"
#include "sim/mill/simulated_mill.hpp"

namespace stencil::board::sim {

// After each machine update, the leg the mill is cutting is flushed into the machined part (a hook
// of the job's run).
class MillWiring final : public SimMachine {
 public:
  // In virtual time the fake follows the machine side's clock (FakeCy545Clock), which gives its bytes
  // their wire time and its commands the chip's; in real time the wall clock, and it answers from a
  // thread of its own from start_answering() on. See error().
  MillWiring(const SimJob& job, bool realtime);
  ~MillWiring();

  // Empty when the driver's port is open; else why not.
  [[nodiscard]] const std::string& error() const override { return error_; }
  [[nodiscard]] hal::cy545::Cy545Link& link() override { return *link_; }
  [[nodiscard]] const hal::cy545::Cy545Link& link() const { return *link_; }
  [[nodiscard]] const char* link_error() const override { return link_->last_error(); }
  [[nodiscard]] hal::Clock& clock() override { return fast_clock_ ? static_cast<hal::Clock&>(*fast_clock_) : wall_clock_; }
  // Virtual time only (in real time the fake's thread owns it): the fault hooks at the line's far end.
  [[nodiscard]] stencil::sim::cy545::FakeCy545& fake() { return fake_; }
  [[nodiscard]] stencil::sim::MachinedPart& machined() override { return machined_; }
  [[nodiscard]] const stencil::sim::MachinedPart& machined() const override { return machined_; }
  // The simulated mill itself (virtual time: no thread of the fake's is running), for what a person
  // at it would see.
  [[nodiscard]] const stencil::sim::SimulatedMill& mill() const { return mill_; }

  // Real time: the fake answers from its own thread until stop_answering().
  void start_answering() override;
  void stop_answering() override;

  // Once homed: the machined part counts from where the mill is now.
  void arm() override;

  void after_machine_update() override;

  // At the end, once the machine side has stopped the mill (at now_ns): its power as the board's
  // latches leave it, then a second later, when the watchdog relay has dropped what the driver could
  // not turn off because its heartbeat stopped with the job. What the machinist finds at the mill.
  void leave(SimResult& result, bool stop_confirmed, hal::MonotonicNs now_ns) override;

 private:
  // Runs `inspect()` with the fake's thread held off, when it has one.
  template <typename Inspect>
  void with_the_fake_still(Inspect&& inspect) {
    if (runner_ != nullptr) {
      runner_->with_fake([&](stencil::sim::cy545::FakeCy545&) { inspect(); });
    } else {
      inspect();
    }
  }

  stencil::sim::SimulatedMill mill_;
  hal::MonotonicNs epoch_ns_;
  stencil::sim::cy545::FakeCy545 fake_;
  hal::MonotonicNs relay_ns_;  // the watchdog relay's time (the mill's truth)
  std::optional<stencil::sim::cy545::FakeCy545Clock> fast_clock_;
  hal::posix_clock::MonotonicClock wall_clock_;
  stencil::sim::MachinedPart machined_;
  hal::cy545::SerialPort port_;
  std::unique_ptr<hal::cy545::Cy545Link> link_;
  std::unique_ptr<stencil::sim::cy545::FakeCy545Runner> runner_;
  std::string error_;
};

}  // namespace stencil::board::sim
