#include "firmware/services/report/job_report.hpp"

#include <algorithm>
#include <cmath>
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

nlohmann::json xyz(const double (&v)[3]) { return nlohmann::json::array({v[0], v[1], v[2]}); }

// Infinity has no JSON: an unlimited speed is null.
nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json limits_json(std::uint64_t from_cycle, double from_s, const OperatorLimits& limits) {
  return {{"from_cycle", from_cycle},
          {"from_s", from_s},
          {"coupling_n_per_device_mm", limits.coupling_n_per_device_mm},
          {"force_limit_n", limits.force_limit_n},
          {"speed_limit_mm_per_s", finite_or_null(limits.speed_limit_mm_per_s)},
          {"damping_n_s_per_m", limits.damping_n_s_per_m},
          {"friction", limits.friction},
          {"speed_limiting", engine::speed_limiting_name(limits.speed_limiting)}};
}

// The commands in order, the limits in force from each change on, the pauses and the positions.
nlohmann::json operator_json(const OperatorRecord& r, control::SafeReason safe_state, nlohmann::json& limits_out,
                             nlohmann::json& positions_out) {
  nlohmann::json list = nlohmann::json::array();
  nlohmann::json limits = nlohmann::json::array({limits_json(0, 0.0, r.initial_limits)});
  OperatorLimits now = r.initial_limits;
  std::uint64_t pauses = 0;
  for (const control::CommandEvent& e : r.commands) {
    const double t_s = static_cast<double>(e.time_ns - r.start_ns) / 1e9;
    nlohmann::json item = {{"cycle", e.cycle},
                           {"t_s", t_s},
                           {"kind", control::command_kind_name(e.kind)},
                           {"source", control::command_source_name(e.source)},
                           {"outcome", control::command_outcome_name(e.outcome)},
                           {"waited_cycles", e.cycle - std::min(e.cycle, e.queued_after_cycle)}};
    const bool set = control::is_parameter(e.kind);
    if (set) {
      item["parameter"] = control::parameter_name(e.kind);
      item["asked"] = finite_or_null(e.asked);
      item["applied"] = finite_or_null(e.applied);
    }
    list.push_back(item);
    pauses += e.kind == control::CommandKind::Pause && e.outcome == control::CommandOutcome::Done ? 1 : 0;
    if (set && e.outcome != control::CommandOutcome::Refused) {
      switch (e.kind) {
        case control::CommandKind::SetCoupling:
          now.coupling_n_per_device_mm = e.applied;
          break;
        case control::CommandKind::SetForceLimit:
          now.force_limit_n = e.applied;
          break;
        case control::CommandKind::SetDamping:
          now.damping_n_s_per_m = e.applied;
          break;
        case control::CommandKind::SetFriction:
          now.friction = e.applied;
          break;
        case control::CommandKind::SetSpeedLimiting:
          now.speed_limiting = e.applied == 0.0 ? engine::SpeedLimiting::Cap : engine::SpeedLimiting::Penalty;
          break;
        default:
          now.speed_limit_mm_per_s = e.applied;
          break;
      }
      limits.push_back(limits_json(e.cycle, t_s, now));
    }
  }
  limits_out = limits;
  const FinalPositions& p = r.positions;
  positions_out = {{"device_mm", xyz(p.device_mm)},
                   {"virtual_tool", {{"work_mm", xyz(p.virtual_work_mm)}, {"machine_mm", xyz(p.virtual_machine_mm)}}},
                   {"mill_commanded", {{"work_mm", xyz(p.mill_work_mm)}, {"machine_mm", xyz(p.mill_machine_mm)}}}};
  return {{"count", r.commands.size() + r.commands_unlisted},
          {"unlisted", r.commands_unlisted},
          {"pauses", pauses},
          {"machine_holds", r.machine_holds},
          {"machine_held_updates", r.machine_held_updates},
          {"safe_state_source", safe_state == control::SafeReason::None
                                    ? nlohmann::json(nullptr)
                                    : nlohmann::json(control::command_source_name(r.safe_source))},
          {"list", list}};
}

}  // namespace

Quantiles quantiles_of(const control::MicrosecondHistogram& histogram) {
  return {histogram.quantile_us(0.5), histogram.quantile_us(0.99), histogram.quantile_us(0.999),
          static_cast<double>(histogram.max_ns()) / 1000.0};
}

bool write_job_report(const std::string& path, const JobFigures& f, const nlohmann::json& board_sections,
                      std::string& error) {
  nlohmann::json report = {
      {"provenance", provenance_json(f.provenance)},
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
  nlohmann::json limits;
  nlohmann::json positions;
  report["commands"] = operator_json(f.operator_record, f.safe_state, limits, positions);
  report["limits"] = limits;
  report["final_positions"] = positions;
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
