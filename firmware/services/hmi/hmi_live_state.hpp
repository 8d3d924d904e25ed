// What the operator display shows, read from a controller's state feed at each tick and turned into
// JSON frames: deltas at 20 Hz, and a whole snapshot for a client that is new or missed a frame.
// Lives in stencil-display only; not thread-safe by itself (the web server's one thread owns it).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "firmware/services/display_link/controller_client.hpp"
#include "firmware/services/display_link/display_wire.hpp"
#include "firmware/services/display_link/state_feed.hpp"

namespace stencil::hmi {

// JSON as the page receives it: compact, any invalid UTF-8 (a name from a file) replaced, never a
// throw.
[[nodiscard]] std::string json_text(const nlohmann::json& value);

class LiveState {
 public:
  LiveState();

  // At each tick, with the controller's feed (null: none yet). A feed of a new job starts everything
  // again from it; the same feed's newest state is read (touched triangles as deltas, the stock only
  // when it changed, the largest force since the last tick).
  void update(const display_link::FeedView* feed, std::uint64_t feed_generation);
  // Where the link stands, for the page (shown with every frame).
  void set_link(display_link::LinkState state, const std::string& detail);

  [[nodiscard]] bool has_feed() const { return attached_; }
  // What changed since the last frame(), as one frame; advances. `server` is the server's own
  // counters, sent as they are.
  [[nodiscard]] nlohmann::json frame(std::uint64_t sequence, const nlohmann::json& server);
  // Everything as of the last frame(): a client starts (or starts again) from this.
  [[nodiscard]] nlohmann::json snapshot(std::uint64_t sequence, const nlohmann::json& server) const;
  // The part's mesh and which triangles are reachable (GET /api/part), built once per job.
  [[nodiscard]] const std::string& part_json() const { return part_json_; }

  // Why a reset may not be asked now ("" when it may): the display's decision; the controller and
  // then the cycle check again.
  [[nodiscard]] std::string reset_refusal() const;
  // Why a pause or a resume may not be asked now ("" when it may).
  [[nodiscard]] std::string pause_refusal(display_link::RequestKind kind) const;
  [[nodiscard]] const display_link::RequestLimits& limits() const { return limits_; }

  [[nodiscard]] double coverage() const;
  [[nodiscard]] std::uint32_t touched_count() const { return figures_.touched_count; }
  [[nodiscard]] std::uint64_t job_id() const { return job_id_; }
  [[nodiscard]] bool virtual_clock() const { return virtual_clock_; }
  [[nodiscard]] const display_link::Figures& figures() const { return figures_; }

 private:
  void attach(const display_link::FeedView& feed);
  void common(nlohmann::json& out) const;
  [[nodiscard]] static nlohmann::json stock_grid(const display_link::StockGridHeader& grid, const std::vector<float>& heights);

  bool attached_ = false;
  std::uint64_t generation_ = 0;
  std::uint64_t job_id_ = 0;
  std::uint32_t triangles_ = 0, reachable_ = 0;
  display_link::RequestLimits limits_{};
  display_link::ResetRule reset_rule_{};
  bool virtual_clock_ = false;
  std::string program_;
  std::string part_json_;

  display_link::LinkState link_ = display_link::LinkState::Waiting;
  std::string link_detail_;

  display_link::Figures figures_{};
  std::vector<std::uint8_t> touched_bits_, touched_sent_;  // now, and as the last frame left the clients
  std::vector<std::uint32_t> new_touched_;                 // since the last frame
  float force_peak_n_ = 0.0F;                              // since the last frame
  std::uint64_t force_cycle_ = 0;                          // the newest cycle the peak has seen
  std::uint64_t stock_sequence_ = 0;
  display_link::StockGridHeader grid_{}, grid_sent_{};
  display_link::FeedMachine machine_{};
  std::vector<float> heights_, heights_sent_;
  std::uint64_t frames_ = 0;
};

}  // namespace stencil::hmi
