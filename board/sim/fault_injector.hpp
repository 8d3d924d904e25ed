// FaultInjector: the job's one injected fault (stencil-sim --inject KIND@S), put in where it happens
// (the device's side, the far end of the serial line, the host's scheduling) before the first cycle
// at or after its time: a hook of the job's run, virtual time only.
#pragma once

#include "board/sim/fault_injection.hpp"
#include "board/sim/simulated_device_wiring.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/runtime/job_hooks.hpp"
#include "sim/cy545/fake_cy545.hpp"

namespace stencil::board::sim {

class FaultInjector final : public runtime::JobHooks {
 public:
  // Everything must outlive the injector; `period_ns` is the cycle's.
  FaultInjector(const FaultInjection& fault, SimulatedDeviceWiring& device, stencil::sim::cy545::FakeCy545& fake,
                control::Controller& controller, hal::MonotonicNs period_ns)
      : fault_(fault), device_(device), fake_(fake), controller_(controller), period_ns_(period_ns) {}

  bool before_cycle(const runtime::CycleTime& time) override;
  // An overrun storm: from the injection on, every cycle starts and ends 1.5 periods late, as on a
  // host that stalls the thread (lateness counts then, as on the wall clock).
  [[nodiscard]] hal::MonotonicNs lateness_ns() const override {
    return injected_ == FaultKind::OverrunStorm ? 3 * period_ns_ / 2 : 0;
  }

  // What was injected (None: nothing yet) and when, simulated seconds (negative: never).
  [[nodiscard]] FaultKind injected() const { return injected_; }
  [[nodiscard]] double injected_s() const { return injected_s_; }

 private:
  const FaultInjection fault_;
  SimulatedDeviceWiring& device_;
  stencil::sim::cy545::FakeCy545& fake_;
  control::Controller& controller_;
  hal::MonotonicNs period_ns_;
  FaultKind injected_ = FaultKind::None;
  double injected_s_ = -1.0;
};

}  // namespace stencil::board::sim
