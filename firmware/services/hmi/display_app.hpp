// stencil-display's work: one controller's link (its socket and state feed) and the web server,
// joined on the server's one thread. Each tick polls the link, reads the feed into the live state
// and hands the server a frame (and a snapshot when a client needs one); each browser request is
// parsed and checked here, then sent to the controller, whose answer goes back to that browser.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <memory>
#include <string>

#include "firmware/services/display_link/controller_client.hpp"
#include "firmware/services/hmi/hmi_live_state.hpp"
#include "firmware/services/hmi/hmi_requests.hpp"
#include "firmware/services/hmi/web_server.hpp"

namespace stencil::hmi {

struct DisplayAppOptions {
  std::string controller_socket;
  WebServerOptions web;
  bool quiet = false;  // no lines on stdout when the link changes
};

struct DisplayCounters {
  std::uint64_t malformed = 0;   // browser messages that were not a request
  std::uint64_t refused = 0;     // refused here or by the controller
  std::uint64_t accepted = 0;    // accepted by the controller
  std::uint64_t forwarded = 0;   // sent to the controller
};

class DisplayApp {
 public:
  explicit DisplayApp(DisplayAppOptions options);
  ~DisplayApp();
  DisplayApp(const DisplayApp&) = delete;
  DisplayApp& operator=(const DisplayApp&) = delete;

  [[nodiscard]] bool start(std::string& error);
  void stop();
  [[nodiscard]] std::string url() const { return web_->url(); }
  [[nodiscard]] WebServerStats web_stats() const { return web_->stats(); }
  [[nodiscard]] DisplayCounters counters() const;

  // The reply to one browser message (public so the rules are tested without a socket): an error,
  // a refusal, or "" when it went to the controller (whose answer comes later, by send()).
  [[nodiscard]] std::string handle_message(ClientId client, bool may_control, std::string_view text);

 private:
  void tick(bool snapshot_wanted, std::string& frame, std::string& snapshot);
  [[nodiscard]] nlohmann::json server_json() const;
  void take_answers();

  DisplayAppOptions options_;
  display_link::ControllerClient client_;
  LiveState state_;
  std::unique_ptr<WebServer> web_;
  struct Pending {
    ClientId client;
    Request request;
  };
  std::map<std::uint32_t, Pending> pending_;  // by request id, until the controller answers
  std::uint32_t next_id_ = 1;
  std::uint64_t sequence_ = 0;
  display_link::LinkState shown_ = display_link::LinkState::Waiting;
  bool said_ = false;
  mutable std::mutex counters_mutex_;
  DisplayCounters counters_;
};

}  // namespace stencil::hmi
