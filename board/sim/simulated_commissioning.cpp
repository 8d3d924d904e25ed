#include "board/sim/simulated_commissioning.hpp"

#include <cmath>
#include <cstdio>

#include "board/sim/mill_wiring.hpp"

namespace stencil::board::sim {
namespace {

// Reads the tool's true position along the axis, world mm, to the indicator's 0.001 mm: the mill's
// steps since home at the mill's true steps per mm, the way the rig's geometry maps them.
class SimulatedMachinist final : public sherline_suzuki::CommissioningOperator {
 public:
  SimulatedMachinist(const SimRig& rig, const MillWiring& mill, const std::function<void(const std::string&)>& say)
      : rig_(rig), mill_(mill), say_(say) {}

  void say(const std::string& line) override { say_(line); }

  bool reading(int axis, const std::string& question, const std::function<void()>&, double& mm) override {
    const auto a = static_cast<std::size_t>(axis);
    const auto steps = mill_.mill().axis_position_steps(static_cast<stencil::sim::Axis>(axis));
    const double world = rig_.mill_truth.machine_sign[a] * static_cast<double>(steps) / rig_.mill_truth.steps_per_mm;
    mm = std::round(world * 1000.0) / 1000.0 + 0.0;  // no -0.000
    char answer[64];
    std::snprintf(answer, sizeof answer, " -> %.3f (the simulated machinist)", mm);
    say_(question + answer);
    return true;
  }

 private:
  const SimRig& rig_;
  const MillWiring& mill_;
  const std::function<void(const std::string&)>& say_;
};

}  // namespace

sherline_suzuki::CommissioningResult commission_simulated_rig(const SimJob& job,
                                                              const sherline_suzuki::CommissioningSettings& settings,
                                                              const std::atomic<bool>* interrupted,
                                                              const std::function<void(const std::string&)>& say) {
  MillWiring mill(job, false);
  if (!mill.error().empty()) {
    sherline_suzuki::CommissioningResult failed;
    failed.findings.push_back(mill.error());
    return failed;
  }
  SimulatedMachinist machinist(job.rig, mill, say);
  return sherline_suzuki::commission(job.rig.facts, settings, mill.link(), mill.clock(), machinist, interrupted);
}

}  // namespace stencil::board::sim
