// Commissioning (board/sherline_suzuki/commissioning.hpp) on the simulated rig, in virtual time: the
// fake CY545 and the simulated mill as the job's (its truth may differ from the configuration), and a
// simulated machinist whose dial indicator reads where the mill's steps really put the tool.
#pragma once

#include <atomic>

#include "board/sherline_suzuki/commissioning.hpp"
#include "board/sim/sim_job.hpp"

namespace stencil::board::sim {

[[nodiscard]] sherline_suzuki::CommissioningResult commission_simulated_rig(
    const SimJob& job, const sherline_suzuki::CommissioningSettings& settings, const std::atomic<bool>* interrupted,
    const std::function<void(const std::string&)>& say);

}  // namespace stencil::board::sim
