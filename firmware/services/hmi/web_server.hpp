// The operator display's web server (stencil-display only; never in a controller's process):
// Boost.Beast over one Asio thread, serving the built page from memory, two JSON documents the
// display provides (/api/part, /api/status), and a WebSocket at /ws that sends the display's frames
// and takes the operator's requests.
//
// Every client is bounded before anything is allocated for it: at most max_connections sockets at
// once (more are closed on accept), a request's header within header_limit_bytes and
// header_timeout_ms (a slow-loris sender is dropped), a WebSocket message refused from its frame
// header when it declares more than max_message_bytes (read_message_max), at most max_clients
// WebSockets, an Origin naming this server required for the upgrade, and a client that takes no
// bytes for write_timeout_ms dropped. Each client has one frame in flight at most: a frame that
// finds the previous one still being written is dropped for it, and its next is a snapshot.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "firmware/services/hmi/hmi_access.hpp"

namespace stencil::hmi {

using ClientId = std::uint64_t;

struct WebServerOptions {
  HmiEndpoint endpoint;
  std::string token;                 // "" on loopback: every local client may control
  std::string assets_dir;            // the built page: only its files are served (read once at start)
  int max_clients = 16;              // WebSockets at once
  int max_connections = 64;          // sockets at once, HTTP and WebSocket; more are closed on accept
  std::size_t header_limit_bytes = 8192;
  std::size_t max_message_bytes = 1024;  // a client's WebSocket message; a larger one closes it
  int header_timeout_ms = 5000;      // the whole request header, from accept
  int write_timeout_ms = 2000;       // a client that takes no bytes for this long is dropped
  double frame_hz = 20.0;
};

struct WebServerStats {
  std::uint64_t ticks = 0;              // frame ticks
  std::uint64_t messages_sent = 0;      // frames, snapshots and replies, to all clients
  std::uint64_t bytes_sent = 0;
  std::uint64_t snapshots_sent = 0;
  std::uint64_t frames_dropped = 0;     // a client still writing the last one: a snapshot next
  std::uint64_t messages_received = 0;  // WebSocket text messages passed to on_message
  std::uint64_t malformed = 0;          // binary, fragmented or too long (the too-long close the client)
  std::uint64_t connections_refused = 0;  // over max_connections or max_clients, or a foreign/missing Origin
  std::uint64_t clients_dropped = 0;    // write timeout, header timeout, or a read error
  std::uint32_t connections = 0;        // sockets open now
  std::uint32_t clients = 0;            // WebSockets open now
};

// The display's side, each called on the server's one thread (never two at once, never after stop()).
struct WebHandlers {
  // At frame_hz: the frame every client gets, and when `snapshot_wanted` (a client is new or missed
  // a frame) the snapshot such a client gets instead. Either may be left empty: nothing is sent.
  std::function<void(bool snapshot_wanted, std::string& frame, std::string& snapshot)> tick;
  // A client's text message; the reply (if not empty) goes to that client before its next frame.
  std::function<std::string(ClientId client, bool may_control, std::string_view text)> on_message;
  // The first message a new WebSocket client gets.
  std::function<std::string(bool may_control)> hello;
  // GET /api/part and /api/status: the body (JSON), or an empty string for 503 (not yet known).
  std::function<std::string()> part;
  std::function<std::string()> status;
};

class WebServer {
 public:
  WebServer(const WebServerOptions& options, WebHandlers handlers);
  ~WebServer();  // stop()
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  // Reads the page, listens, starts the thread; false with the reason (no page, the port taken, a
  // bad endpoint or token).
  [[nodiscard]] bool start(std::string& error);
  void stop();  // closes every socket and joins the thread
  [[nodiscard]] int port() const;  // as bound (for port 0)
  [[nodiscard]] std::string url() const;

  // A message to one client (a late reply): from a handler only (the server's thread); dropped when
  // the client is gone or already has 8 replies waiting.
  void send(ClientId client, std::string text);

  [[nodiscard]] WebServerStats stats() const;  // any thread

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stencil::hmi
