// The operator display's server: civetweb (Debian's libcivetweb) serving the built page from its
// asset folder, the part's mesh, and a WebSocket at /ws that sends 20 Hz frames and takes the
// operator's requests. It runs on threads of its own; the boards feed it from their records and
// machine threads and forward its commands into the cycle's command ring (whose one producer they
// are). Nothing here is ever called from the cycle.
//
// A slow or stalled client never holds anyone else up: each client has a sender thread of its own
// and a one-frame mailbox. A frame that finds the mailbox still full is dropped for that client,
// and its next frame is a whole snapshot instead, so a dropped frame never leaves it wrong.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/services/hmi/hmi_access.hpp"
#include "firmware/services/hmi/hmi_live_state.hpp"
#include "firmware/services/hmi/hmi_requests.hpp"
#include "firmware/core/tables/part_tables.hpp"

struct mg_context;
struct mg_connection;

namespace stencil::hmi {

struct HmiServerOptions {
  HmiEndpoint endpoint;
  std::string token;       // "" on loopback: every local client may change parameters
  std::string assets_dir;  // the built page (index.html, app.js, ...): only these files are served
  int max_clients = 8;
  double frame_hz = 20.0;
  bool virtual_clock = false;  // the cycle runs on a virtual clock: its loop timing is 0 by construction
  int write_timeout_ms = 1000;  // a client that takes no bytes for this long is dropped
};

struct HmiServerStats {
  std::uint64_t frames = 0;            // frames built (each tick)
  std::uint64_t messages_sent = 0;     // to all clients: frames, snapshots and replies
  std::uint64_t bytes_sent = 0;        // their payload bytes
  std::uint64_t snapshots_sent = 0;
  std::uint64_t frames_dropped = 0;    // a client's mailbox still full: it gets a snapshot next
  std::uint64_t malformed = 0;         // messages that could not be parsed (answered with an error)
  std::uint64_t refused = 0;           // well-formed requests refused (watch-only, limits, reset rule)
  std::uint64_t accepted = 0;          // requests passed on to the cycle
  std::uint64_t connections_refused = 0;  // over max_clients
  std::uint64_t clients_dropped = 0;   // a write failed or timed out
  std::uint32_t clients = 0;           // connected now
};

[[nodiscard]] HmiLimits limits_of(const control::ControllerConfig& config);

class HmiServer final : public control::DisplayFeed {
 public:
  // The limits a request is checked against come from the cycle's own config (its force limit is
  // the board's; its move limits the mill's speed).
  HmiServer(const HmiServerOptions& options, const tables::PartTables& part, const control::ControllerConfig& config);
  virtual ~HmiServer();
  HmiServer(const HmiServer&) = delete;
  HmiServer& operator=(const HmiServer&) = delete;

  // Loads the assets, listens and starts the frame thread; false with the reason (no page built,
  // the port taken, a bad token).
  [[nodiscard]] bool start(std::string& error);
  void stop();
  [[nodiscard]] int port() const { return port_; }  // as bound (for port 0)
  [[nodiscard]] std::string url() const;

  // From the board's records thread (or the fast loop): every journal record, every telemetry.
  void on_record(const control::JournalRecord& record) override;
  void on_telemetry(const control::Telemetry& telemetry) override;
  // From the thread that owns the machine side, after an update: at most 10 times a second it
  // samples the stock model (on the calling thread, outside the lock).
  void on_machine(double lag_mm, const control::CommandedStock& model) override;
  // The same with the stock already sampled (on_machine's second half).
  void on_stock(double lag_mm, StockGrid stock);
  // Before the cycle starts: a resumed job's touched set.
  void seed_touched(const engine::TriangleSet& touched) override;
  // The operator's accepted requests, for the command ring, oldest first (at most 16 wait).
  [[nodiscard]] bool pop_command(control::Command& command) override;

  [[nodiscard]] HmiServerStats stats() const;

  // The reply to one client message, as the WebSocket handler gives it ({"type":"accepted"|
  // "refused"|"error", ...}); public so the rules are tested without a socket.
  [[nodiscard]] std::string handle_message(bool may_control, std::string_view text);

 private:
  struct Client;
  static int on_http(mg_connection* conn, void* self);
  static int on_ws_connect(const mg_connection* conn, void* self);
  static void on_ws_ready(mg_connection* conn, void* self);
  static int on_ws_data(mg_connection* conn, int bits, char* data, std::size_t length, void* self);
  static void on_ws_close(const mg_connection* conn, void* self);
  static int serve_http(mg_connection* conn, HmiServer& self);
  void frame_loop();
  void build_frames();
  void send_loop(const std::shared_ptr<Client>& client);
  void send_messages(const std::shared_ptr<Client>& client);
  [[nodiscard]] nlohmann::json server_json() const;

  HmiServerOptions options_;
  HmiLimits limits_;
  mg_context* context_ = nullptr;
  int port_ = 0;
  std::map<std::string, std::pair<std::string, std::string>> assets_;  // path -> (content type, bytes)
  std::string part_json_;

  mutable std::mutex state_mutex_;
  LiveState state_;
  std::deque<control::Command> commands_;
  std::uint64_t sequence_ = 0;

  mutable std::mutex clients_mutex_;
  std::vector<std::shared_ptr<Client>> clients_;

  mutable std::mutex stats_mutex_;
  HmiServerStats stats_;

  std::mutex machine_mutex_;  // only one machine thread samples at a time
  std::int64_t last_machine_ns_ = 0;

  std::atomic<bool> stopping_{false};
  std::mutex frame_mutex_;
  std::condition_variable frame_wake_;
  std::thread frame_thread_;
};

}  // namespace stencil::hmi
