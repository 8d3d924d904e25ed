// The controller's end of the request channel: a Unix-domain socket (owner-only) that displays of
// the same user connect to, served on a thread of its own (never the cycle's). Each display says
// Hello and gets the state feed's descriptor; each request it sends is decoded (every byte
// checked), rate-limited (a Stop never is), decided (the limits, the reset rule, the cycle's state)
// and, if accepted, pushed into the display's command ring, which the cycle drains each period;
// every display gets an answer. Nothing here waits for a display: a display
// that does not take its answers is dropped.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/display_link/display_wire.hpp"

namespace stencil::display_link {

struct RequestServerOptions {
  std::string socket_path;
  int max_displays = 8;            // more are closed at once (counted in peers_refused)
  double requests_per_s = 10.0;    // each display's steady rate; more are refused
  double request_burst = 10.0;
};

class RequestServer {
 public:
  // Why `request` may not go to the cycle, or "" to accept it (called on the server's thread).
  using Decide = std::function<std::string(const Request& request)>;

  // `commands` is the cycle's ring for the displays: this server's thread is its one producer.
  RequestServer(RequestServerOptions options, int feed_fd, Decide decide, control::CommandRing& commands);
  ~RequestServer();  // stop()
  RequestServer(const RequestServer&) = delete;
  RequestServer& operator=(const RequestServer&) = delete;

  // Binds the socket (a stale one from a dead controller is replaced; a live one is refused) and
  // starts the thread; false with the reason.
  [[nodiscard]] bool start(std::string& error);
  void stop();  // closes every connection, removes the socket, joins

  [[nodiscard]] RequestCounters counters() const;
  [[nodiscard]] const std::string& path() const { return options_.socket_path; }

 private:
  struct Peer;
  void serve();
  void accept_peers(std::deque<Peer>& peers);
  bool read_peer(Peer& peer);  // false: close it
  bool answer(Peer& peer, const Message& message, bool with_feed);
  void handle(Peer& peer, const Message& message);

  RequestServerOptions options_;
  int feed_fd_;
  Decide decide_;
  int listen_fd_ = -1;
  int wake_fd_ = -1;
  std::thread thread_;
  std::atomic<bool> stopping_{false};

  control::CommandRing& commands_;
  double last_stop_s_ = -1.0;      // the server thread's: when it last pushed a stop
  std::uint64_t stops_merged_ = 0;  // stops within 100 ms of the last one: the same stop

  std::atomic<std::uint64_t> connected_{0}, seen_{0}, accepted_{0}, refused_{0}, rate_limited_{0}, malformed_{0},
      peers_refused_{0};
};

}  // namespace stencil::display_link
