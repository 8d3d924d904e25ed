// A simulated job's result from its parts once they have stopped: the cycle's and the machine's
// statistics, the ground truth of what was machined beside the controller's own model of it, and
// the process's memory.
#pragma once

#include <chrono>
#include <cstdint>

#include "board/sim/sim_machine.hpp"
#include "board/sim/sim_job.hpp"
#include "firmware/core/stencil/triangle_set.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "firmware/runtime/job.hpp"
#include "firmware/runtime/run_outcome.hpp"

namespace stencil::board::sim {

// The fraction of the part's reachable triangles in `touched` (1 when none is reachable).
[[nodiscard]] double reachable_coverage(const tables::PartTables& part, const engine::TriangleSet& touched);

// This process's resident memory now (kB).
[[nodiscard]] std::int64_t resident_kb();

// What the mill machined into `result`: volumes, gouge, the stock's and the part's heights.
void fill_machined(SimResult& result, const stencil::sim::MachinedPart& machined);

// Fills the rest of `result` (what the run's hooks reported is in it already): in real time the
// wake-up latency is the cycle's; in virtual time there is none to speak of.
void fill_result(SimResult& result, const runtime::Job& job, const runtime::RunOutcome& outcome, const SimMachine& mill,
                 bool realtime, std::chrono::steady_clock::time_point wall_start);

}  // namespace stencil::board::sim
