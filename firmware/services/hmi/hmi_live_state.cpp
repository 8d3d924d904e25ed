#include "firmware/services/hmi/hmi_live_state.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/tables/table_format.hpp"

namespace stencil::hmi {
namespace {

double rounded(double value, double step) { return std::isfinite(value) ? std::round(value / step) * step : 0.0; }

// The event list, oldest first: the commands the cycle took and the safe states it entered.
nlohmann::json events_json(const display_link::Figures& f) {
  nlohmann::json list = nlohmann::json::array();
  const std::uint64_t total = f.events_total;
  const std::uint64_t first = total > display_link::kFeedEvents ? total - display_link::kFeedEvents : 0;
  for (std::uint64_t n = first; n < total; ++n) {
    const display_link::FeedEvent& e = f.events[n % display_link::kFeedEvents];
    nlohmann::json item = {{"n", n},
                           {"cycle", e.cycle},
                           {"t", rounded(static_cast<double>(e.time_ns - f.first_time_ns) / 1e9, 1e-3)},
                           {"source", control::command_source_name(e.source)}};
    if (e.type == display_link::FeedEventType::SafeState) {
      item["type"] = "safe_state";
      item["reason"] = control::safe_reason_name(e.reason);
    } else {
      item["type"] = control::command_kind_name(e.kind);
      item["outcome"] = control::command_outcome_name(e.outcome);
      if (control::is_parameter(e.kind)) {
        item["parameter"] = control::parameter_name(e.kind);
        item["asked"] = std::isfinite(e.asked) ? nlohmann::json(e.asked) : nlohmann::json(nullptr);
        item["applied"] = std::isfinite(e.applied) ? nlohmann::json(e.applied) : nlohmann::json(nullptr);
      }
    }
    list.push_back(std::move(item));
  }
  return list;
}

nlohmann::json point(const double (&p)[3]) {
  return nlohmann::json::array({rounded(p[0], 1e-4), rounded(p[1], 1e-4), rounded(p[2], 1e-4)});
}

nlohmann::json bins(const display_link::TimingHistogram& timing) {
  return {{"bin_us", display_link::kTimingBinUs},
          {"counts", timing.counts},
          {"max_us", rounded(static_cast<double>(timing.max_ns) / 1000.0, 0.1)}};
}

}  // namespace

std::string json_text(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

LiveState::LiveState() { link_detail_ = "no controller yet"; }

void LiveState::set_link(display_link::LinkState state, const std::string& detail) {
  link_ = state;
  link_detail_ = detail;
}

void LiveState::attach(const display_link::FeedView& feed) {
  const display_link::FeedHeader& h = feed.header();
  attached_ = true;
  job_id_ = h.job_id;
  triangles_ = h.triangle_count;
  reachable_ = h.reachable_triangle_count;
  limits_ = h.limits;
  reset_rule_ = h.reset_rule;
  virtual_clock_ = h.virtual_clock != 0;
  program_.assign(h.program, strnlen(h.program, sizeof h.program));
  figures_ = display_link::Figures{};
  touched_bits_.assign((triangles_ + 7) / 8, 0);
  touched_sent_ = touched_bits_;
  new_touched_.clear();
  force_peak_n_ = 0.0F;
  force_cycle_ = 0;
  stock_sequence_ = 0;
  grid_ = grid_sent_ = display_link::StockGridHeader{};
  heights_.clear();
  heights_sent_.clear();
  nlohmann::json vertices = nlohmann::json::array();
  nlohmann::json reachable = nlohmann::json::array();
  for (std::uint32_t t = 0; t < triangles_; ++t) {
    const float* v = feed.vertices(t);
    for (int i = 0; i < 9; ++i) {
      vertices.push_back(rounded(static_cast<double>(v[i]), 1e-4));
    }
    reachable.push_back((feed.flags(t) & tables::kTriangleReachable) != 0 ? 1 : 0);
  }
  part_json_ = json_text({{"triangles", triangles_},
                        {"job", std::to_string(job_id_)},
                        {"vertices", std::move(vertices)},
                        {"reachable", std::move(reachable)},
                        {"tool_diameter_mm", h.tool_diameter_mm},
                        {"workspace_mm", {h.workspace_mm[0], h.workspace_mm[1], h.workspace_mm[2]}}});
}

void LiveState::update(const display_link::FeedView* feed, std::uint64_t feed_generation) {
  if (feed == nullptr) {
    return;
  }
  if (!attached_ || feed_generation != generation_) {
    attach(*feed);
    generation_ = feed_generation;
  }
  display_link::Figures now{};
  if (feed->read(now)) {
    figures_ = now;
  }
  display_link::FeedMachine machine{};
  if (feed->read(machine)) {
    machine_ = machine;
  }
  feed->touched(touched_bits_);
  for (std::size_t byte = 0; byte < touched_bits_.size(); ++byte) {
    const auto added = static_cast<std::uint8_t>(touched_bits_[byte] & ~touched_sent_[byte]);
    for (int bit = 0; added != 0 && bit < 8; ++bit) {
      if ((added & (1U << bit)) != 0) {
        new_touched_.push_back(static_cast<std::uint32_t>(byte * 8 + static_cast<std::size_t>(bit)));
      }
    }
    touched_sent_[byte] |= touched_bits_[byte];
  }
  if (figures_.have_record != 0) {
    force_peak_n_ = std::max(force_peak_n_, feed->force_peak(force_cycle_, figures_.cycle));
    force_cycle_ = figures_.cycle;
  }
  const std::uint64_t sequence = feed->stock_sequence();
  if (sequence != stock_sequence_) {
    auto stock = std::make_unique<display_link::FeedStock>();
    if (feed->read(*stock) && stock->grid.columns >= 0 && stock->grid.rows >= 0 &&
        std::int64_t{stock->grid.columns} * stock->grid.rows <= display_link::kStockCellsMax) {
      stock_sequence_ = sequence;
      grid_ = stock->grid;
      heights_.assign(stock->heights_mm, stock->heights_mm + grid_.columns * grid_.rows);
    }
  }
}

double LiveState::coverage() const {
  if (reachable_ == 0) {
    return attached_ ? 1.0 : 0.0;
  }
  return static_cast<double>(figures_.reachable_touched) / static_cast<double>(reachable_);
}

std::string LiveState::reset_refusal() const {
  if (!attached_) {
    return "no controller";
  }
  if (figures_.phase == display_link::JobPhase::Ended) {
    return "the job has ended";
  }
  return display_link::reset_refusal(figures_.have_telemetry != 0, figures_.telemetry, reset_rule_);
}

std::string LiveState::pause_refusal(display_link::RequestKind kind) const {
  if (!attached_) {
    return "no controller";
  }
  if (figures_.phase == display_link::JobPhase::Ended) {
    return "the job has ended";
  }
  return display_link::pause_refusal(kind, figures_.have_telemetry != 0, figures_.telemetry);
}

nlohmann::json LiveState::stock_grid(const display_link::StockGridHeader& g, const std::vector<float>& heights) {
  nlohmann::json values = nlohmann::json::array();
  for (const float h : heights) {
    values.push_back(rounded(static_cast<double>(h), 1e-3));
  }
  return {{"x0", g.x0_mm}, {"y0", g.y0_mm}, {"cell", g.cell_mm}, {"columns", g.columns}, {"rows", g.rows},
          {"heights", std::move(values)}};
}

void LiveState::common(nlohmann::json& out) const {
  const display_link::Figures& f = figures_;
  const control::Telemetry& telemetry = f.telemetry;
  out["controller"] = {{"state", display_link::link_state_name(link_)},
                       {"detail", link_detail_},
                       {"program", program_},
                       {"job", std::to_string(job_id_)},
                       {"ended", f.phase == display_link::JobPhase::Ended},
                       {"end", std::string(f.end_text, strnlen(f.end_text, sizeof f.end_text))}};
  out["virtual_clock"] = virtual_clock_;
  out["t"] = rounded(static_cast<double>(f.time_ns - f.first_time_ns) / 1e9, 1e-3);
  out["cycle"] = f.cycle;
  out["tool"] = point(f.virtual_tip_mm);
  out["probe"] = point(f.probe_mm);
  out["force"] = nlohmann::json::array({rounded(static_cast<double>(f.force_n[0]), 1e-3),
                                        rounded(static_cast<double>(f.force_n[1]), 1e-3),
                                        rounded(static_cast<double>(f.force_n[2]), 1e-3)});
  out["touched_count"] = f.touched_count;
  out["coverage"] = rounded(coverage(), 1e-5);
  out["lag_mm"] = rounded(grid_.lag_mm, 1e-3);
  const control::SafeReason reason = f.have_telemetry != 0 ? telemetry.safe_reason : f.record_safe_reason;
  const std::string refusal = reset_refusal();
  out["safe"] = {{"active", reason != control::SafeReason::None},
                 {"reason", control::safe_reason_name(reason)},
                 {"reset_allowed", refusal.empty()},
                 {"reset_refusal", refusal},
                 {"reset_requests", telemetry.reset_requests},
                 {"last_reset", control::reset_outcome_name(telemetry.last_reset)}};
  out["params"] = {{"coupling", rounded(telemetry.coupling_n_per_device_mm, 1e-4)},
                   {"force_limit", rounded(telemetry.force_limit_n, 1e-4)},
                   {"speed_limit", std::isfinite(telemetry.speed_limit_mm_per_s)
                                       ? nlohmann::json(rounded(telemetry.speed_limit_mm_per_s, 1e-4))
                                       : nlohmann::json(nullptr)},
                   {"damping", rounded(telemetry.damping_n_s_per_m, 1e-4)},
                   {"friction", rounded(telemetry.friction, 1e-4)},
                   {"speed_limiting", engine::speed_limiting_name(telemetry.speed_limiting)},
                   {"requests", telemetry.parameter_requests},
                   {"last", control::parameter_name(telemetry.last_parameter)},
                   {"last_outcome", control::parameter_outcome_name(telemetry.last_parameter_outcome)}};
  out["safe"]["source"] = control::command_source_name(telemetry.safe_source);
  out["paused"] = telemetry.paused;
  // The position readout: device space; the virtual tool and the mill's last target in work (the
  // part's) and machine (from home) coordinates.
  out["dro"] = {{"device", point(f.device_mm)},
                {"tool_work", point(f.virtual_tip_mm)},
                {"tool_machine", point(f.virtual_machine_mm)},
                {"mill_work", point(machine_.work_mm)},
                {"mill_machine", point(machine_.machine_mm)},
                {"mill_held", machine_.held != 0},
                {"mill_updates", machine_.updates}};
  out["events"] = events_json(f);
  const display_link::RequestCounters& r = f.requests;
  out["link"] = {{"displays", r.displays_connected}, {"accepted", r.accepted}, {"refused", r.refused},
                 {"rate_limited", r.rate_limited},  {"malformed", r.malformed}, {"peers_refused", r.peers_refused}};
}

nlohmann::json LiveState::frame(std::uint64_t sequence, const nlohmann::json& server) {
  nlohmann::json out;
  if (!attached_) {
    out = {{"type", "waiting"},
           {"seq", sequence},
           {"controller", {{"state", display_link::link_state_name(link_)}, {"detail", link_detail_}}},
           {"server", server}};
    return out;
  }
  out["type"] = "frame";
  out["seq"] = sequence;
  common(out);
  out["force_peak"] = rounded(static_cast<double>(force_peak_n_), 1e-3);
  out["touched"] = new_touched_;
  // Stock cells that changed by more than a micrometre since the last frame: [index, height].
  nlohmann::json cells = nlohmann::json::array();
  if (heights_sent_.size() != heights_.size() || grid_sent_.columns != grid_.columns) {
    out["stock_grid"] = stock_grid(grid_, heights_);
  } else {
    for (std::size_t i = 0; i < heights_.size(); ++i) {
      if (std::abs(heights_[i] - heights_sent_[i]) > 1e-3F) {
        cells.push_back({i, rounded(static_cast<double>(heights_[i]), 1e-3)});
      }
    }
  }
  out["stock"] = std::move(cells);
  // The loop's histograms change slowly: once a second.
  if (frames_ % 20 == 0) {
    out["loop"] = {{"wakeup", bins(figures_.wakeup)}, {"compute", bins(figures_.compute)},
                   {"telemetry_gaps", figures_.telemetry_gaps}};
  }
  out["server"] = server;
  new_touched_.clear();
  force_peak_n_ = 0.0F;
  heights_sent_ = heights_;
  grid_sent_ = grid_;
  ++frames_;
  return out;
}

nlohmann::json LiveState::snapshot(std::uint64_t sequence, const nlohmann::json& server) const {
  if (!attached_) {
    nlohmann::json out = {{"type", "waiting"},
                          {"seq", sequence},
                          {"controller", {{"state", display_link::link_state_name(link_)}, {"detail", link_detail_}}},
                          {"server", server}};
    return out;
  }
  nlohmann::json out;
  out["type"] = "snapshot";
  out["seq"] = sequence;
  common(out);
  out["force_peak"] = 0.0;
  // Built after the tick's frame: everything as of now; the next frame's changes apply on top.
  std::vector<std::uint32_t> ids;
  for (std::size_t byte = 0; byte < touched_sent_.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      const auto id = static_cast<std::uint32_t>(byte * 8 + static_cast<std::size_t>(bit));
      if ((touched_sent_[byte] & (1U << bit)) != 0) {
        ids.push_back(id);
      }
    }
  }
  out["touched"] = std::move(ids);
  out["stock_grid"] = stock_grid(grid_sent_, heights_sent_);
  out["stock"] = nlohmann::json::array();
  out["loop"] = {{"wakeup", bins(figures_.wakeup)}, {"compute", bins(figures_.compute)},
                 {"telemetry_gaps", figures_.telemetry_gaps}};
  out["limits"] = {{"board_force_limit", limits_.board_force_limit_n},
                   {"mill_speed", limits_.mill_speed_mm_per_s},
                   {"min_coupling", limits_.min_coupling_n_per_device_mm},
                   {"max_coupling", limits_.max_coupling_n_per_device_mm},
                   {"max_damping", limits_.max_damping_n_s_per_m}};
  out["server"] = server;
  return out;
}

}  // namespace stencil::hmi
