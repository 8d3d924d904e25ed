#include "firmware/services/hmi/hmi_live_state.hpp"

#include <algorithm>
#include <cmath>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/stencil/contact_query.hpp"

namespace stencil::hmi {
namespace {

double rounded(double value, double step) { return std::isfinite(value) ? std::round(value / step) * step : 0.0; }

nlohmann::json point(const double (&p)[3]) {
  return nlohmann::json::array({rounded(p[0], 1e-4), rounded(p[1], 1e-4), rounded(p[2], 1e-4)});
}

nlohmann::json point(const Eigen::Vector3d& p) {
  return nlohmann::json::array({rounded(p.x(), 1e-4), rounded(p.y(), 1e-4), rounded(p.z(), 1e-4)});
}

nlohmann::json bins(const TimingBins& timing) {
  return {{"bin_us", TimingBins::kBinUs}, {"counts", timing.counts}, {"max_us", rounded(static_cast<double>(timing.max_ns) / 1000.0, 0.1)}};
}

}  // namespace

StockGrid coarse_stock(const control::CommandedStock& model) {
  StockGrid grid;
  if (!model.ready() || model.columns() <= 0 || model.rows() <= 0) {
    return grid;
  }
  const int longer = std::max(model.columns(), model.rows());
  const int factor = std::max(1, (longer + 99) / 100);
  grid.columns = (model.columns() + factor - 1) / factor;
  grid.rows = (model.rows() + factor - 1) / factor;
  grid.cell_mm = model.cell_mm() * factor;
  grid.x0_mm = model.block().low_mm.x();
  grid.y0_mm = model.block().low_mm.y();
  grid.heights_mm.assign(static_cast<std::size_t>(grid.columns) * static_cast<std::size_t>(grid.rows),
                         static_cast<float>(model.block().high_mm.z()));
  // Every third model cell in each direction is enough: the narrowest cut is a tool's width, many
  // model cells wide; this keeps the sampling to about a millisecond on the machine side's thread.
  const int stride = std::max(1, factor / 3);
  for (int row = 0; row < model.rows(); row += stride) {
    for (int column = 0; column < model.columns(); column += stride) {
      float& cell = grid.heights_mm[static_cast<std::size_t>(row / factor) * static_cast<std::size_t>(grid.columns) +
                                    static_cast<std::size_t>(column / factor)];
      cell = std::min(cell, static_cast<float>(model.height(column, row)));
    }
  }
  return grid;
}

void TimingBins::add(std::int64_t ns) {
  const double us = static_cast<double>(std::max<std::int64_t>(ns, 0)) / 1000.0;
  const int bin = std::min(kBins - 1, static_cast<int>(us / kBinUs));
  ++counts[static_cast<std::size_t>(bin)];
  max_ns = std::max(max_ns, ns);
}

LiveState::LiveState(const tables::PartTables& part, const control::ControllerConfig& config, const HmiLimits& limits)
    : part_(part), config_(config), limits_(limits), touched_(std::make_unique<engine::TriangleSet>()) {
  contact_tool_ready_ = engine::build_contact_tool(part.tool.spec, control::touch_distance_mm(config), contact_tool_);
  touched_->observe(&LiveState::heard_touched, this);
  telemetry_.coupling_n_per_device_mm = config.haptic.coupling_n_per_device_mm;
  telemetry_.force_limit_n = config.haptic.max_force_n;
  telemetry_.speed_limit_mm_per_s = config.max_axis_move_mm / config.period_s;
}

void LiveState::heard_touched(void* self, std::uint32_t id) {
  auto& state = *static_cast<LiveState*>(self);
  state.new_touched_.push_back(id);
  if (id < state.part_.triangle_count() && (state.part_.triangle_flags[id] & tables::kTriangleReachable) != 0) {
    ++state.reachable_touched_;
  }
}

void LiveState::seed_touched(const engine::TriangleSet& touched) {
  for (std::uint32_t t = 0; t < part_.triangle_count(); ++t) {
    if (touched.contains(t)) {
      touched_->insert(t);
    }
  }
}

void LiveState::on_record(const control::JournalRecord& record) {
  if (!have_record_) {
    first_time_ns_ = record.time_ns;
    have_record_ = true;
  }
  // The cycle marks the touched set at the virtual tool each cycle; where its count grew, the same
  // marking here gives the same triangles (a cycle whose count did not grow added none).
  if (record.touched_triangles > touched_->count() && contact_tool_ready_) {
    const Eigen::Vector3d tip(record.virtual_tip_mm[0], record.virtual_tip_mm[1], record.virtual_tip_mm[2]);
    static_cast<void>(engine::mark_touched(part_, contact_tool_, {tip, Eigen::Vector3d::UnitZ()},
                                           control::touch_distance_mm(config_), *touched_));
  }
  const Eigen::Vector3d f(static_cast<double>(record.force_n[0]), static_cast<double>(record.force_n[1]),
                          static_cast<double>(record.force_n[2]));
  const double force = f.norm();
  force_peak_n_ = std::max(force_peak_n_, force);
  last_record_ = record;
}

void LiveState::on_telemetry(const control::Telemetry& telemetry) {
  if (have_telemetry_ && telemetry.cycle > telemetry_.cycle + 1) {
    telemetry_gaps_ += telemetry.cycle - telemetry_.cycle - 1;  // dropped by a full ring
  }
  wakeup_.add(telemetry.wakeup_ns);
  if (telemetry.cycle > 1) {
    compute_.add(telemetry.last_compute_ns);
  }
  telemetry_ = telemetry;
  have_telemetry_ = true;
  ++telemetry_seen_;
}

void LiveState::on_machine(double lag_mm, StockGrid stock) {
  lag_mm_ = lag_mm;
  stock_ = std::move(stock);
}

double LiveState::coverage() const {
  if (part_.header.reachable_triangle_count == 0) {
    return 1.0;
  }
  return static_cast<double>(reachable_touched_) / static_cast<double>(part_.header.reachable_triangle_count);
}

std::string LiveState::reset_refusal() const {
  if (!have_telemetry_ || telemetry_.safe_reason == control::SafeReason::None) {
    return "not in a safe state";
  }
  if (telemetry_.device_still_s < config_.still_time_s) {
    return "hold the handle still (" + std::to_string(static_cast<int>(config_.still_time_s * 1000)) + " ms)";
  }
  if (telemetry_.device_to_tool_mm > config_.reset_distance_mm) {
    char text[120];
    std::snprintf(text, sizeof text, "bring the handle to the virtual tool: %.1f mm away, at most %.1f mm",
                  telemetry_.device_to_tool_mm, config_.reset_distance_mm);
    return text;
  }
  return "";
}

void LiveState::common(nlohmann::json& out) const {
  const control::JournalRecord& r = last_record_;
  out["t"] = rounded(static_cast<double>(r.time_ns - first_time_ns_) / 1e9, 1e-3);
  out["cycle"] = r.cycle;
  out["tool"] = point(r.virtual_tip_mm);
  out["probe"] = point(motion::device_to_world(config_.frames, Eigen::Vector3d(r.device_mm[0], r.device_mm[1], r.device_mm[2])));
  out["force"] = nlohmann::json::array(
      {rounded(static_cast<double>(r.force_n[0]), 1e-3), rounded(static_cast<double>(r.force_n[1]), 1e-3),
       rounded(static_cast<double>(r.force_n[2]), 1e-3)});
  out["touched_count"] = touched_->count();
  out["coverage"] = rounded(coverage(), 1e-5);
  out["lag_mm"] = rounded(lag_mm_, 1e-3);
  const control::SafeReason reason = have_telemetry_ ? telemetry_.safe_reason : r.safe_reason;
  const std::string refusal = reset_refusal();
  out["safe"] = {{"active", reason != control::SafeReason::None},
                 {"reason", control::safe_reason_name(reason)},
                 {"reset_allowed", refusal.empty()},
                 {"reset_refusal", refusal},
                 {"reset_requests", telemetry_.reset_requests},
                 {"last_reset", control::reset_outcome_name(telemetry_.last_reset)}};
  out["params"] = {{"coupling", rounded(telemetry_.coupling_n_per_device_mm, 1e-4)},
                   {"force_limit", rounded(telemetry_.force_limit_n, 1e-4)},
                   {"speed_limit", std::isfinite(telemetry_.speed_limit_mm_per_s)
                                       ? nlohmann::json(rounded(telemetry_.speed_limit_mm_per_s, 1e-4))
                                       : nlohmann::json(nullptr)},
                   {"requests", telemetry_.parameter_requests},
                   {"last", control::parameter_name(telemetry_.last_parameter)},
                   {"last_outcome", control::parameter_outcome_name(telemetry_.last_parameter_outcome)}};
}

nlohmann::json LiveState::frame(std::uint64_t sequence, const nlohmann::json& server) {
  nlohmann::json out;
  out["type"] = "frame";
  out["seq"] = sequence;
  common(out);
  out["force_peak"] = rounded(force_peak_n_, 1e-3);
  out["touched"] = new_touched_;
  // Stock cells that changed by more than a micrometre since the last frame: [index, height].
  nlohmann::json cells = nlohmann::json::array();
  if (stock_sent_.heights_mm.size() != stock_.heights_mm.size()) {
    out["stock_grid"] = {{"x0", stock_.x0_mm}, {"y0", stock_.y0_mm}, {"cell", stock_.cell_mm},
                         {"columns", stock_.columns}, {"rows", stock_.rows}, {"heights", nlohmann::json::array()}};
    for (const float h : stock_.heights_mm) {
      out["stock_grid"]["heights"].push_back(rounded(static_cast<double>(h), 1e-3));
    }
  } else {
    for (std::size_t i = 0; i < stock_.heights_mm.size(); ++i) {
      if (std::abs(stock_.heights_mm[i] - stock_sent_.heights_mm[i]) > 1e-3F) {
        cells.push_back({i, rounded(static_cast<double>(stock_.heights_mm[i]), 1e-3)});
      }
    }
  }
  out["stock"] = std::move(cells);
  // The loop's histograms change slowly: once a second.
  if (frames_ % 20 == 0) {
    out["loop"] = {{"wakeup", bins(wakeup_)}, {"compute", bins(compute_)}, {"telemetry_gaps", telemetry_gaps_}};
  }
  out["server"] = server;
  new_touched_.clear();
  force_peak_n_ = 0.0;
  stock_sent_ = stock_;
  ++frames_;
  return out;
}

nlohmann::json LiveState::snapshot(std::uint64_t sequence, const nlohmann::json& server) const {
  nlohmann::json out;
  out["type"] = "snapshot";
  out["seq"] = sequence;
  common(out);
  out["force_peak"] = 0.0;
  std::vector<std::uint32_t> ids;
  ids.reserve(touched_->count());
  for (std::uint32_t t = 0; t < part_.triangle_count(); ++t) {
    if (touched_->contains(t)) {
      ids.push_back(t);
    }
  }
  out["touched"] = std::move(ids);
  // As the last frame left the clients: the next frame's changes apply on top of this.
  nlohmann::json heights = nlohmann::json::array();
  for (const float h : stock_sent_.heights_mm) {
    heights.push_back(rounded(static_cast<double>(h), 1e-3));
  }
  out["stock_grid"] = {{"x0", stock_sent_.x0_mm}, {"y0", stock_sent_.y0_mm}, {"cell", stock_sent_.cell_mm},
                       {"columns", stock_sent_.columns}, {"rows", stock_sent_.rows}, {"heights", std::move(heights)}};
  out["stock"] = nlohmann::json::array();
  out["loop"] = {{"wakeup", bins(wakeup_)}, {"compute", bins(compute_)}, {"telemetry_gaps", telemetry_gaps_}};
  out["limits"] = {{"board_force_limit", limits_.board_force_limit_n},
                   {"mill_speed", limits_.mill_speed_mm_per_s},
                   {"min_coupling", limits_.min_coupling_n_per_device_mm},
                   {"max_coupling", limits_.max_coupling_n_per_device_mm}};
  out["server"] = server;
  return out;
}

nlohmann::json LiveState::part_mesh() const {
  nlohmann::json vertices = nlohmann::json::array();
  nlohmann::json reachable = nlohmann::json::array();
  for (std::uint32_t t = 0; t < part_.triangle_count(); ++t) {
    for (const tables::PackedPoint& v : part_.triangles[t].vertices) {
      vertices.push_back(rounded(static_cast<double>(v.x_mm), 1e-4));
      vertices.push_back(rounded(static_cast<double>(v.y_mm), 1e-4));
      vertices.push_back(rounded(static_cast<double>(v.z_mm), 1e-4));
    }
    reachable.push_back((part_.triangle_flags[t] & tables::kTriangleReachable) != 0 ? 1 : 0);
  }
  return {{"triangles", part_.triangle_count()},
          {"vertices", std::move(vertices)},
          {"reachable", std::move(reachable)},
          {"tool_diameter_mm", part_.tool.spec.diameter_mm},
          {"workspace_mm", {part_.header.workspace_mm[0], part_.header.workspace_mm[1], part_.header.workspace_mm[2]}}};
}

}  // namespace stencil::hmi
