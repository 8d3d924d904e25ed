#include "firmware/services/report/job_report.hpp"

#include <fstream>

namespace stencil::report {
namespace {

nlohmann::json quantiles_json(const Quantiles& q) {
  return {{"p50", q.p50}, {"p99", q.p99}, {"p999", q.p999}, {"max", q.max}};
}

nlohmann::json nullable(const std::string& text) { return text.empty() ? nlohmann::json(nullptr) : nlohmann::json(text); }

// The whole job, over every run its journal recorded and this one: a fresh job is one run.
nlohmann::json job_json(const JobFigures& f) {
  nlohmann::json safe_states = nlohmann::json::array();
  for (const journal::RecordedFault& fault : f.earlier.faults) {
    safe_states.push_back({{"run", fault.segment}, {"cycle", fault.cycle}, {"reason", control::safe_reason_name(fault.reason)}});
  }
  if (f.safe_state != control::SafeReason::None) {
    safe_states.push_back({{"run", f.earlier.segments}, {"cycle", f.cycles}, {"reason", control::safe_reason_name(f.safe_state)}});
  }
  // How each run ended: the journal's End record, or none (killed, crashed); this run as it did.
  nlohmann::json endings = nlohmann::json::array();
  const auto ending_name = [](bool recorded, control::SafeReason reason) -> std::string {
    return !recorded ? "unrecorded (killed or crashed)" : reason == control::SafeReason::None ? "finished" : control::safe_reason_name(reason);
  };
  for (std::size_t run = 0; run < f.earlier.endings.size(); ++run) {
    const journal::RunEnding& e = f.earlier.endings[run];
    endings.push_back({{"run", run}, {"ending", ending_name(e.recorded, e.reason)}, {"run_cycles", e.cycles}});
  }
  endings.push_back({{"run", f.earlier.segments}, {"ending", ending_name(true, f.safe_state)}, {"run_cycles", f.cycles}});
  return {{"runs", f.earlier.segments + 1},
          {"run_endings", endings},
          {"total_cycles", f.earlier.cycles + f.cycles},
          {"earlier_machine_commands", f.earlier.machine_commands},
          {"earlier_machined_legs", f.earlier.machined_legs},
          {"touched_recorded", f.earlier.touched_recorded},
          {"touched_rebuilt", f.touched_rebuilt},
          {"safe_states", safe_states}};
}

// `from`'s keys into `into`, objects merged key by key at any depth; anything else (null too, unlike
// a JSON merge patch, which would delete the key) replaces what was there.
void merge_into(nlohmann::json& into, const nlohmann::json& from) {
  for (auto item = from.begin(); item != from.end(); ++item) {
    nlohmann::json& target = into[item.key()];
    if (item.value().is_object() && target.is_object()) {
      merge_into(target, item.value());
    } else {
      target = item.value();
    }
  }
}

}  // namespace

Quantiles quantiles_of(const control::MicrosecondHistogram& histogram) {
  return {histogram.quantile_us(0.5), histogram.quantile_us(0.99), histogram.quantile_us(0.999),
          static_cast<double>(histogram.max_ns()) / 1000.0};
}

bool write_job_report(const std::string& path, const JobFigures& f, const nlohmann::json& board_sections,
                      std::string& error) {
  nlohmann::json report = {
      {"job", job_json(f)},
      {"cycles", f.cycles},
      {"overruns", f.overruns},
      {"missed_periods", f.missed_periods},
      {"wakeup_latency_us", quantiles_json(f.wakeup_latency_us)},
      {"compute_us", quantiles_json(f.compute_us)},
      {"max_force_n", f.max_force_n},
      {"max_offset_mm", f.max_offset_mm},
      {"machine", {{"updates", f.machine_updates}, {"max_lag_mm", f.machine_max_lag_mm},
                   {"stop_confirmed", f.machine_stop_confirmed}, {"error", nullable(f.machine_error)}}},
      {"stock_model", {{"removed_volume_mm3", f.model_removed_volume_mm3}}},
      {"safe_state", f.safe_state == control::SafeReason::None ? nlohmann::json(nullptr)
                                                                : nlohmann::json(control::safe_reason_name(f.safe_state))},
  };
  if (board_sections.is_object()) {
    merge_into(report, board_sections);
  }
  std::ofstream out(path);
  out << report.dump(2) << '\n';
  if (!out) {
    error = path + ": cannot be written";
    return false;
  }
  return true;
}

}  // namespace stencil::report
