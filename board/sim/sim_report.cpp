// Report and summary of a simulated job.
#include "board/sim/sim_report.hpp"

#include <cstdio>

#include <nlohmann/json.hpp>

#include "board/sim/sim_facts.hpp"
#include "firmware/services/report/job_report.hpp"

namespace stencil::board::sim {
namespace {

// The figures every job reports, as the simulation measured them.
report::JobFigures figures_of(const SimResult& r) {
  report::JobFigures f;
  f.cycles = r.cycles;
  f.overruns = r.overruns;
  f.missed_periods = r.missed_periods;
  f.wakeup_latency_us = r.wakeup_latency_us;
  f.compute_us = r.compute_us;
  f.max_force_n = r.max_force_n;
  f.max_offset_mm = r.max_offset_mm;
  f.machine_updates = r.machine_updates;
  f.machine_max_lag_mm = r.machine_max_lag_mm;
  f.machine_stop_confirmed = r.machine_stop_confirmed;
  f.machine_error = r.machine_error;
  f.model_removed_volume_mm3 = r.model_removed_volume_mm3;
  f.safe_state = r.safe_state;
  f.earlier = r.earlier;
  f.operator_record = r.operator_record;
  f.touched_rebuilt = r.touched_rebuilt;
  return f;
}

// What only the simulation measures: the ground truth of what was cut, the injected fault, the
// simulated mill as the stop left it, the journal and the process's memory.
// The G-code program's section: which program, how it ran, and (as the operator) each source line
// whose move the stencil refused or shortened with how deep it would have gone.
nlohmann::json gcode_section(const SimResult& r) {
  nlohmann::json refused = nlohmann::json::array();
  for (const GcodeRefusal& refusal : r.gcode_refused) {
    refused.push_back({{"line", refusal.line}, {"depth_mm", refusal.depth_mm}});
  }
  return {{"program", r.gcode_program},
          {"run", r.gcode_direct ? "direct" : "operator"},
          {"refused", r.gcode_direct ? nlohmann::json(nullptr) : refused}};
}

nlohmann::json simulation_sections(const SimResult& r) {
  return {
      {"job", {{"total_simulated_s", r.earlier.recorded_s + r.simulated_s}}},
      {"fault", r.fault_kind == FaultKind::None
                    ? nlohmann::json(nullptr)
                    : nlohmann::json{{"kind", fault_kind_name(r.fault_kind)},
                                     {"injected_s", r.fault_injected_s},
                                     {"safe_state_s", r.safe_state_s},
                                     {"force_zero_s", r.force_zero_s},
                                     {"machine_stopped_s", r.machine_stopped_s}}},
      {"stock_model", {{"max_difference_mm", r.model_max_difference_mm}}},
      {"journal", r.journal_path.empty() ? nlohmann::json(nullptr)
                                         : nlohmann::json{{"path", r.journal_path},
                                                          {"cycle_records", r.journal_records},
                                                          {"machine_records", r.journal_machine_records},
                                                          {"command_records", r.journal_command_records},
                                                          {"error", r.journal_error.empty() ? nlohmann::json(nullptr)
                                                                                            : nlohmann::json(r.journal_error)}}},
      {"memory_kb", {{"after_setup", r.rss_after_setup_kb}, {"at_end", r.rss_at_end_kb}, {"most", r.max_rss_kb}}},
      {"simulated_s", r.simulated_s},
      {"wall_s", r.wall_s},
      {"gouge", {{"max_depth_mm", r.gouge_measured ? nlohmann::json(r.gouge_max_depth_mm) : nlohmann::json(nullptr)},
                 {"volume_mm3", r.gouge_volume_mm3}}},
      {"removed", {{"volume_mm3", r.removed_volume_mm3}}},
      {"unmachined",
       {{"volume_mm3", r.unmachined_volume_mm3},
        {"fraction", r.reachable_volume_mm3 > 0.0 ? r.unmachined_volume_mm3 / r.reachable_volume_mm3 : 0.0},
        {"reachable_volume_mm3", r.reachable_volume_mm3},
        {"standoff_mm", r.standoff_mm},
        {"standoff_volume_mm3", r.allowance_volume_mm3}}},
      {"coverage_fraction", r.coverage_fraction},
      {"complete", r.complete},
      {"machine", {{"take_ups", r.machine_take_ups},
                   {"safe_state_s", r.safe_state_s >= 0.0 ? nlohmann::json(r.safe_state_s) : nlohmann::json(nullptr)},
                   {"stopped_s", r.machine_stopped_s >= 0.0 ? nlohmann::json(r.machine_stopped_s) : nlohmann::json(nullptr)},
                   {"spindle_on_after_stop", r.mill_spindle_on_after_stop},
                   {"drivers_on_after_stop", r.mill_drivers_on_after_stop},
                   {"watchdog_relay_dropped_power", r.mill_relay_dropped_power},
                   {"on_after_watchdog_relay", r.mill_on_after_relay}}},
  };
}

}  // namespace

bool write_stock_csv(const std::string& path, const SimResult& r, std::string& error) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (out == nullptr) {
    error = path + ": cannot be written";
    return false;
  }
  for (int row = 0; row < r.rows; ++row) {
    for (int column = 0; column < r.columns; ++column) {
      std::fprintf(out, column == 0 ? "%.5f" : ",%.5f",
                   r.stock_heights[static_cast<std::size_t>(row) * static_cast<std::size_t>(r.columns) + static_cast<std::size_t>(column)]);
    }
    std::fputc('\n', out);
  }
  if (std::fclose(out) != 0) {
    error = path + ": cannot be written";
    return false;
  }
  return true;
}

bool write_report_json(const std::string& path, const SimResult& r, const report::Provenance& provenance,
                       std::string& error) {
  report::JobFigures figures = figures_of(r);
  figures.provenance = provenance;
  nlohmann::json sections = simulation_sections(r);
  if (!r.gcode_program.empty()) {
    sections["gcode"] = gcode_section(r);  // only with a program: every other job's report is as before
  }
  return report::write_job_report(path, figures, sections, error);
}

std::string summary(const SimResult& r) {
  char text[1024];
  const double fraction = r.reachable_volume_mm3 > 0.0 ? r.unmachined_volume_mm3 / r.reachable_volume_mm3 : 0.0;
  std::snprintf(text, sizeof text,
                "simulated %.1f s in %.1f s (%llu cycles, %llu machine updates)\n"
                "gouge: %s mm deepest, %.3f mm3 under the part's top\n"
                "stock removed %.1f mm3; unmachined %.2f mm3 = %.2f %% of what this tool can reach (beyond the %.3f mm "
                "standoff, which leaves %.2f mm3)\n"
                "coverage %.1f %% of reachable triangles; max force %.2f N; max offset %.3f mm; max machine lag %.3f mm\n"
                "cycle compute p50 %.1f us, p99.9 %.1f us, max %.1f us (wall clock)\n"
                "safe state: %s\n",
                r.simulated_s, r.wall_s, static_cast<unsigned long long>(r.cycles),
                static_cast<unsigned long long>(r.machine_updates),
                r.gouge_measured ? std::to_string(r.gouge_max_depth_mm).c_str() : "not measured (not a ball end mill)",
                r.gouge_volume_mm3, r.removed_volume_mm3, r.unmachined_volume_mm3, 100.0 * fraction,
                r.standoff_mm, r.allowance_volume_mm3,
                100.0 * r.coverage_fraction, r.max_force_n, r.max_offset_mm, r.machine_max_lag_mm, r.compute_us.p50,
                r.compute_us.p999, r.compute_us.max,
                r.safe_state == control::SafeReason::None ? "none" : control::safe_reason_name(r.safe_state));
  std::string out = text;
  if (r.wakeup_latency_us.max > 0.0) {  // real time: how late the cycle woke, and what that cost
    std::snprintf(text, sizeof text, "cycle wake-up latency p99 %.1f us, p99.9 %.1f us, max %.1f us; %llu overruns, %llu periods skipped\n",
                  r.wakeup_latency_us.p99, r.wakeup_latency_us.p999, r.wakeup_latency_us.max,
                  static_cast<unsigned long long>(r.overruns), static_cast<unsigned long long>(r.missed_periods));
    out += text;
  }
  if (!r.gcode_program.empty() && !r.gcode_direct) {
    out += "gcode: " + std::to_string(r.gcode_refused.size()) + " line" + (r.gcode_refused.size() == 1 ? "" : "s") +
           " of " + r.gcode_program + " refused or shortened by the stencil" + (r.gcode_refused.empty() ? "" : ":");
    for (const GcodeRefusal& refusal : r.gcode_refused) {
      std::snprintf(text, sizeof text, " line %d (%.3f mm deep)", refusal.line, refusal.depth_mm);
      out += text;
    }
    out += "\n";
  }
  if (!r.journal_error.empty()) {
    out += "journal: " + r.journal_error + "\n";
  }
  if (!r.machine_error.empty()) {
    out += "machine: " + r.machine_error + "\n";
  }
  if (r.mill_spindle_on_after_stop || r.mill_drivers_on_after_stop) {
    out += std::string("mill: WARNING after the stop the spindle was ") + (r.mill_spindle_on_after_stop ? "ON" : "off") +
           " and the drivers " + (r.mill_drivers_on_after_stop ? "ON" : "off") +
           (r.mill_on_after_relay ? "; still on after the watchdog relay's second\n"
                                  : "; the watchdog relay dropped them a second later\n");
  }
  return out;
}

}  // namespace stencil::board::sim
