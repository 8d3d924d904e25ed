// The controller's side of its displays: a control::DisplayFeed that keeps the state feed (the
// records thread's figures and touched set, the machine thread's stock) and serves the request
// channel. It runs in the controller's process and holds nothing that faces a network: the
// displays (stencil-display) are processes of their own that reach it only through the socket.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/geometry/tool_bsp.hpp"
#include "firmware/core/stencil/triangle_set.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "firmware/services/display_link/request_server.hpp"
#include "firmware/services/display_link/state_feed.hpp"

namespace stencil::display_link {

struct DisplayLinkOptions {
  std::string socket_path;
  std::string program;         // "stencil-sim", shown by the display
  bool virtual_clock = false;  // the cycle runs on a virtual clock: its loop timing is 0 by construction
};

[[nodiscard]] RequestLimits limits_of(const control::ControllerConfig& config);

// The stock as machined, coarse enough to show: the lowest height of the model's cells sampled
// under each display cell (at most ~100 a side).
void coarse_stock(const control::CommandedStock& model, FeedStock& stock);

class DisplayLink final : public control::DisplayFeed {
 public:
  DisplayLink(const tables::PartTables& part, const control::ControllerConfig& config, DisplayLinkOptions options);
  ~DisplayLink();
  DisplayLink(const DisplayLink&) = delete;
  DisplayLink& operator=(const DisplayLink&) = delete;

  // The feed created and filled, the socket bound and served; false with the reason.
  [[nodiscard]] bool start(std::string& error);
  // The job is over: the displays show how, with the last state. Then stop() closes the socket.
  void end(const std::string& how);
  void stop();

  // control::DisplayFeed, from the boards' threads.
  void on_record(const control::JournalRecord& record) override;
  void on_command(const control::CommandEvent& event) override;
  void on_telemetry(const control::Telemetry& telemetry) override;
  void on_machine(const control::MachineView& machine, const control::CommandedStock& model) override;
  void seed_touched(const engine::TriangleSet& touched) override;
  [[nodiscard]] control::CommandRing& commands() override { return commands_; }

  [[nodiscard]] RequestCounters counters() const;
  // The spindle's start, through the link as from the terminal. While the program awaits it, one
  // Start request is accepted (otherwise a Start is refused), and a Stop ends the wait with nothing
  // cut. The program looks with start_answer() and ends the wait with end_start_wait(), which says
  // what came first: a Start or a Stop taken at that very moment still counts, and is never lost.
  enum class StartAnswer : std::uint8_t { None, Start, Stop };
  void await_start() { start_wait_.store(kAwaiting); }
  [[nodiscard]] StartAnswer start_answer() const { return answer_of(start_wait_.load()); }
  StartAnswer end_start_wait() { return answer_of(start_wait_.exchange(kIdle)); }
  [[nodiscard]] const std::string& socket_path() const { return options_.socket_path; }
  [[nodiscard]] int feed_fd() const { return feed_.fd(); }

 private:
  static void heard_touched(void* self, std::uint32_t id);
  [[nodiscard]] std::string decide(const Request& request);
  void publish(bool now);
  void add_event(const FeedEvent& event);

  const tables::PartTables& part_;
  control::ControllerConfig config_;
  DisplayLinkOptions options_;
  geometry::ToolBsp contact_tool_{};
  bool contact_tool_ready_ = false;
  std::unique_ptr<engine::TriangleSet> touched_;  // the mirror of the cycle's set
  std::unique_ptr<Figures> figures_;              // the records thread's, published behind the seqlock
  std::unique_ptr<FeedStock> stock_;              // the machine thread's
  FeedMachine machine_{};                         // the machine thread's
  bool in_safe_state_ = false;                    // the records thread's: the newest record was
  std::chrono::steady_clock::time_point published_{}, sampled_{};
  FeedWriter feed_;
  FeedView own_view_;  // the reset rule reads the newest telemetry back from the feed: no lock
  control::CommandRing commands_;  // the server thread pushes, the cycle pops; outlives both
  std::unique_ptr<RequestServer> server_;
  // The start's wait, shared by the program's thread and the server's: Idle -> Awaiting (the program)
  // -> Started or Stopped (the server, once) -> Idle (the program).
  static constexpr std::uint8_t kIdle = 0, kAwaiting = 1, kStarted = 2, kStopped = 3;
  static StartAnswer answer_of(std::uint8_t state) {
    return state == kStarted ? StartAnswer::Start : state == kStopped ? StartAnswer::Stop : StartAnswer::None;
  }
  std::atomic<std::uint8_t> start_wait_{kIdle};
};

}  // namespace stencil::display_link
