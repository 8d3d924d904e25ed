// What the operator display shows, gathered from the records the cycle already publishes (every
// journal record, the telemetry, the machine side's lag and stock model) and turned into JSON
// frames: deltas at 20 Hz, and a whole snapshot for a client that is new or missed a frame.
//
// Not thread-safe by itself: HmiServer holds it under its lock. Never touched by the cycle.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/hmi/hmi_requests.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/stencil/triangle_set.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::hmi {

// The stock as machined, coarse enough to send: the lowest height of the model's cells sampled
// under each display cell, row-major from the block's low corner.
struct StockGrid {
  double x0_mm = 0.0, y0_mm = 0.0, cell_mm = 0.0;
  int columns = 0, rows = 0;
  std::vector<float> heights_mm;
};

// At most about 100 display cells along the block's longer side (and no finer than the model).
[[nodiscard]] StockGrid coarse_stock(const control::CommandedStock& model);

// Loop timing in 10 us bins up to 500 us, the last bin everything longer.
struct TimingBins {
  static constexpr int kBins = 51;
  static constexpr double kBinUs = 10.0;
  std::array<std::uint64_t, kBins> counts{};
  std::int64_t max_ns = 0;
  void add(std::int64_t ns);
};

class LiveState {
 public:
  LiveState(const tables::PartTables& part, const control::ControllerConfig& config, const HmiLimits& limits);

  // Every cycle's record, in order (lossless): tool, probe, force, touched set, safe state.
  void on_record(const control::JournalRecord& record);
  // Telemetry (may have gaps): loop timing, parameters, reset state.
  void on_telemetry(const control::Telemetry& telemetry);
  // The machine side's newest lag and the stock as it models it.
  void on_machine(double lag_mm, StockGrid stock);
  // Before the cycle starts: a resumed job's touched set, rebuilt from its journal.
  void seed_touched(const engine::TriangleSet& touched);

  // What changed since the last frame(), as one frame; advances. `server` is the server's own
  // counters, sent as they are.
  [[nodiscard]] nlohmann::json frame(std::uint64_t sequence, const nlohmann::json& server);
  // Everything as of the last frame(): a client starts (or starts again) from this.
  [[nodiscard]] nlohmann::json snapshot(std::uint64_t sequence, const nlohmann::json& server) const;
  // The part's mesh and which triangles are reachable (GET /api/part), built once.
  [[nodiscard]] nlohmann::json part_mesh() const;

  // Why a reset may not be asked now ("" when it may): the server's decision; the cycle's rule has
  // the last word.
  [[nodiscard]] std::string reset_refusal() const;

  [[nodiscard]] double coverage() const;
  [[nodiscard]] std::size_t touched_count() const { return touched_->count(); }

 private:
  static void heard_touched(void* self, std::uint32_t id);
  void common(nlohmann::json& out) const;

  const tables::PartTables& part_;
  control::ControllerConfig config_;
  HmiLimits limits_;
  geometry::ToolBsp contact_tool_{};
  bool contact_tool_ready_ = false;
  std::unique_ptr<engine::TriangleSet> touched_;  // the mirror of the cycle's set
  std::vector<std::uint32_t> new_touched_;        // added since the last frame
  std::uint32_t reachable_touched_ = 0;

  bool have_record_ = false;
  std::int64_t first_time_ns_ = 0;
  control::JournalRecord last_record_{};
  double force_peak_n_ = 0.0;                     // since the last frame
  control::Telemetry telemetry_{};
  bool have_telemetry_ = false;
  std::uint64_t telemetry_seen_ = 0, telemetry_gaps_ = 0;
  TimingBins wakeup_, compute_;
  double lag_mm_ = 0.0;
  StockGrid stock_, stock_sent_;                  // now, and as the last frame left the clients
  std::uint64_t frames_ = 0;
};

}  // namespace stencil::hmi
