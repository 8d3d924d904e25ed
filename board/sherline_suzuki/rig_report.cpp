#include "board/sherline_suzuki/rig_report.hpp"

#include <nlohmann/json.hpp>

#include "firmware/services/report/job_report.hpp"

namespace stencil::board::sherline_suzuki {

bool write_rig_report(const std::string& path, const RigResult& r, const std::string& machine_error,
                      const report::Provenance& provenance, std::string& error) {
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
  f.machine_error = machine_error;
  f.model_removed_volume_mm3 = r.model_removed_mm3;
  f.safe_state = r.safe_state;
  f.earlier = r.earlier;
  f.operator_record = r.operator_record;
  f.touched_rebuilt = r.touched_rebuilt;
  f.provenance = provenance;
  const nlohmann::json rig_sections = {
      {"first_fault", r.first_fault == control::SafeReason::None ? nlohmann::json(nullptr)
                                                                 : nlohmann::json(control::safe_reason_name(r.first_fault))},
      {"safe_state_entries", r.safe_state_entries},
      {"resets", {{"accepted", r.resets_accepted}, {"refused", r.resets_refused}}},
      {"run_s", r.run_s},
  };
  return report::write_job_report(path, f, rig_sections, error);
}

}  // namespace stencil::board::sherline_suzuki
