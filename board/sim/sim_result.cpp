// What a simulated job reports of itself.
#include "board/sim/sim_result.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <sys/resource.h>
#include <unistd.h>

#include "firmware/runtime/stall_message.hpp"

namespace stencil::board::sim {
namespace {

// The most this process's resident memory has been (getrusage), kB.
std::int64_t max_resident_kb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

// The cycle's and the machine side's statistics, the job's extremes and how it ended.
void fill_statistics(SimResult& result, const runtime::Job& job, const runtime::RunOutcome& outcome,
                     const SimMachine& mill, bool realtime) {
  const control::Controller& controller = job.controller();
  const control::MachineSide& machine = job.machine();
  result.cycles = controller.statistics().cycles;
  result.overruns = controller.statistics().overruns;
  result.missed_periods = controller.statistics().missed_periods;
  // In virtual time every cycle starts on its deadline: no wake-up latency to speak of.
  result.wakeup_latency_us = realtime ? report::quantiles_of(controller.statistics().wakeup_latency) : Quantiles{0.0, 0.0, 0.0, 0.0};
  result.compute_us = report::quantiles_of(outcome.compute);
  result.simulated_s = outcome.run_s;
  result.operator_record = runtime::operator_record_of(job, outcome);
  result.coverage_fraction = reachable_coverage(*job.parts().part, controller.touched());
  // Over the whole job: a resumed one's journal says what the runs before this one reached.
  result.max_force_n = std::max(controller.max_force_n(), result.earlier.max_force_n);
  result.max_offset_mm = std::max(controller.max_offset_mm(), result.earlier.max_offset_mm);
  result.machine_updates = machine.statistics().updates;
  result.machine_take_ups = machine.statistics().take_ups;
  result.machine_max_lag_mm = machine.statistics().max_lag_mm;
  result.safe_state = controller.safe_reason();
  if (machine.fault() != hal::MachineFault::None || machine.state() == control::MachineSideState::Stopped) {
    result.machine_error = mill.link_error();
  }
  if (machine.stalled()) {
    result.machine_error = runtime::stall_message(machine.stall());
  }
  result.safe_state_s = outcome.safe_state_s;
  result.force_zero_s = outcome.force_zero_s;
  result.machine_stopped_s = outcome.machine_stopped_s;
}

// The controller's model beside what was machined: each model cell against the mill's cell under its centre.
void fill_stock(SimResult& result, const control::CommandedStock& model, const stencil::sim::MachinedPart& machined) {
  fill_machined(result, machined);
  const stencil::sim::StockZmap& stock = machined.stock();
  result.model_removed_volume_mm3 = model.removed_volume_mm3();
  for (int row = 0; row < model.rows(); ++row) {
    for (int column = 0; column < model.columns(); ++column) {
      const double x = model.block().low_mm.x() + (column + 0.5) * model.cell_mm();
      const double y = model.block().low_mm.y() + (row + 0.5) * model.cell_mm();
      const int c = std::clamp(static_cast<int>((x - stock.box().low_mm.x()) / stock.cell_mm()), 0, stock.columns() - 1);
      const int r = std::clamp(static_cast<int>((y - stock.box().low_mm.y()) / stock.cell_mm()), 0, stock.rows() - 1);
      result.model_max_difference_mm = std::max(result.model_max_difference_mm, std::abs(model.height(column, row) - stock.height(c, r)));
    }
  }
}

}  // namespace

// What was machined: the volumes, the gouge and the stock's heights for the picture.
void fill_machined(SimResult& result, const stencil::sim::MachinedPart& machined) {
  stencil::sim::MachinedPart::Volumes volumes = machined.volumes();
  result.gouge_max_depth_mm = machined.max_gouge_mm();
  result.gouge_measured = machined.gouge_measured();
  result.gouge_volume_mm3 = volumes.gouge_mm3;
  result.removed_volume_mm3 = volumes.removed_mm3;
  result.unmachined_volume_mm3 = volumes.unmachined_mm3;
  result.reachable_volume_mm3 = volumes.reachable_mm3;
  result.allowance_volume_mm3 = volumes.allowance_mm3;
  const stencil::sim::StockZmap& stock = machined.stock();
  result.columns = stock.columns();
  result.rows = stock.rows();
  result.cell_mm = stock.cell_mm();
  for (int row = 0; row < stock.rows(); ++row) {
    for (int column = 0; column < stock.columns(); ++column) {
      result.stock_heights.push_back(stock.height(column, row));
    }
  }
  result.part_heights = machined.part_heights();
  result.unmachined_heights = std::move(volumes.unmachined_per_cell_mm);
  result.signed_distance_mm = machined.signed_distances(result.part_heights, kSignedDistanceReachMm);
}

double reachable_coverage(const tables::PartTables& part, const engine::TriangleSet& touched) {
  if (part.header.reachable_triangle_count == 0) {
    return 1.0;
  }
  std::uint32_t covered = 0;
  for (std::uint32_t t = 0; t < part.triangle_count(); ++t) {
    covered += (part.triangle_flags[t] & tables::kTriangleReachable) != 0 && touched.contains(t) ? 1U : 0U;
  }
  return static_cast<double>(covered) / static_cast<double>(part.header.reachable_triangle_count);
}

std::int64_t resident_kb() {
  long pages = 0, resident = 0;
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (statm != nullptr) {
    if (std::fscanf(statm, "%ld %ld", &pages, &resident) != 2) {
      resident = 0;
    }
    std::fclose(statm);
  }
  return static_cast<std::int64_t>(resident) * (sysconf(_SC_PAGESIZE) / 1024);
}

void fill_result(SimResult& result, const runtime::Job& job, const runtime::RunOutcome& outcome, const SimMachine& mill,
                 bool realtime, std::chrono::steady_clock::time_point wall_start) {
  result.rss_at_end_kb = resident_kb();
  result.max_rss_kb = max_resident_kb();
  fill_statistics(result, job, outcome, mill, realtime);
  fill_stock(result, job.model(), mill.machined());
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
}

}  // namespace stencil::board::sim
