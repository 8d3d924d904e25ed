// stencil-display's web server over Boost.Beast: one Asio thread, every socket bounded (see
// web_server.hpp for the bounds and why each one is there).
//
// Everything below runs on the server's one thread except start(), stop(), port(), url() and
// stats(): the sessions, the client table and the counters of open sockets need no lock. Only the
// statistics are shared, under a mutex.
#include "firmware/services/hmi/web_server.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

namespace stencil::hmi {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using error_code = beast::error_code;
using Clock = std::chrono::steady_clock;
using Message = std::shared_ptr<const std::string>;  // a frame is shared by every client it goes to

constexpr std::uintmax_t kMaxAssetBytes = 16u << 20;  // each file of the page
constexpr std::size_t kMaxReplies = 8;                 // waiting per client; more are dropped
constexpr std::size_t kMaxBodyBytes = 1024;            // GET and HEAD only: no request needs a body
// A WebSocket that answers no ping for this long is closed (a browser answers them by itself).
constexpr auto kIdleTimeout = std::chrono::seconds(30);
// After a failed accept (out of descriptors): try again later, not in a busy loop.
constexpr auto kAcceptRetry = std::chrono::milliseconds(100);
constexpr const char* kSecurityPolicy = "default-src 'self'; connect-src 'self' ws: wss:; img-src 'self' data:";
constexpr const char* kNotText = R"({"type":"error","error":"expected one text message of JSON"})";

struct Asset {
  std::string type;
  std::string bytes;
};

std::string content_type(const std::string& path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension == ".html") return "text/html; charset=utf-8";
  if (extension == ".js" || extension == ".mjs") return "text/javascript; charset=utf-8";
  if (extension == ".css") return "text/css; charset=utf-8";
  if (extension == ".json" || extension == ".map") return "application/json";
  if (extension == ".png") return "image/png";
  if (extension == ".svg") return "image/svg+xml";
  if (extension == ".ico") return "image/x-icon";
  return "application/octet-stream";
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// A query parameter's value, %XX and + decoded (as a browser encodes it); "" when absent.
std::string query_value(std::string_view target, std::string_view name) {
  const std::size_t question = target.find('?');
  if (question == std::string_view::npos) {
    return {};
  }
  std::string_view query = target.substr(question + 1);
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
    const std::size_t equals = pair.find('=');
    if (pair.substr(0, equals) != name || equals == std::string_view::npos) {
      continue;
    }
    std::string value;
    for (std::size_t i = equals + 1; i < pair.size(); ++i) {
      if (pair[i] == '%' && i + 2 < pair.size() && hex_digit(pair[i + 1]) >= 0 && hex_digit(pair[i + 2]) >= 0) {
        value.push_back(static_cast<char>(hex_digit(pair[i + 1]) * 16 + hex_digit(pair[i + 2])));
        i += 2;
      } else {
        value.push_back(pair[i] == '+' ? ' ' : pair[i]);
      }
    }
    return value;
  }
  return {};
}

std::string_view path_of(std::string_view target) { return target.substr(0, target.find('?')); }

std::string host_text(const std::string& host) {
  return host.find(':') != std::string::npos ? "[" + host + "]" : host;
}

// The WebSocket's socket. Beast ends a connection it fails (a message over read_message_max, a
// protocol error) or closes by sending its close frame and then reading until the peer closes too;
// a hostile peer never does, and would keep its socket and its client slot until Beast's idle
// timer (seconds). This stream's teardown, found by Beast through argument-dependent lookup before
// the tcp_stream's, closes the socket at once instead: the close frame has gone already.
class ClosingStream : public beast::tcp_stream {
 public:
  explicit ClosingStream(beast::tcp_stream&& stream) : beast::tcp_stream(std::move(stream)) {}
};

template <class Handler>
void async_teardown(beast::role_type, ClosingStream& stream, Handler&& handler) {
  stream.close();
  net::post(stream.get_executor(), beast::bind_front_handler(std::forward<Handler>(handler), error_code{}));
}

class Hub;

// Something the server closes at stop(): a socket still in HTTP, or a WebSocket.
class Connection {
 public:
  virtual ~Connection() = default;
  virtual void close() noexcept = 0;
};

// One open socket (or WebSocket) counted for the admission limits while it lives; moves with the
// socket from the HTTP session to the WebSocket it becomes.
class Slot {
 public:
  Slot(Hub& hub, bool websocket);
  Slot(Slot&& other) noexcept : hub_(std::exchange(other.hub_, nullptr)), websocket_(other.websocket_) {}
  Slot(const Slot&) = delete;
  Slot& operator=(const Slot&) = delete;
  Slot& operator=(Slot&&) = delete;
  ~Slot();

 private:
  Hub* hub_;
  bool websocket_;
};

class WsClient;

// The server's state on its thread. Declared before the io_context are the tables that sessions
// touch from their destructors: handlers still queued when the io_context goes hold sessions, which
// must find these alive.
class Hub {
 public:
  Hub(const WebServerOptions& given, WebHandlers display) : options(given), handlers(std::move(display)) {}

  WebServerOptions options;
  WebHandlers handlers;
  std::map<std::string, Asset> assets;  // by file name, read once at start
  mutable std::mutex stats_mutex;
  WebServerStats stats;
  std::map<std::uint64_t, std::weak_ptr<Connection>> connections;  // every socket, to close at stop
  std::map<ClientId, std::shared_ptr<WsClient>> clients;            // handshaken WebSockets: the frames' readers
  int sockets = 0;     // open now, for max_connections
  int websockets = 0;  // admitted now (from the upgrade's decision), for max_clients
  std::uint64_t next_connection = 1;
  ClientId next_client = 1;
  bool stopping = false;
  Clock::time_point next_tick;

  net::io_context io{1};
  tcp::acceptor acceptor{io};
  net::steady_timer ticker{io};
  net::steady_timer accept_retry{io};

  template <class Change>
  void count(Change&& change) {
    const std::lock_guard<std::mutex> lock(stats_mutex);
    change(stats);
  }

  void accept();
  void schedule_tick();
  void shutdown();
  void send(ClientId client, std::string text);

 private:
  void on_accept(error_code ec, tcp::socket socket);
  void tick();
};

Slot::Slot(Hub& hub, bool websocket) : hub_(&hub), websocket_(websocket) {
  int& open = websocket ? hub.websockets : hub.sockets;
  ++open;
  hub.count([&](WebServerStats& s) { (websocket ? s.clients : s.connections) = static_cast<std::uint32_t>(open); });
}

Slot::~Slot() {
  if (hub_ == nullptr) {
    return;
  }
  int& open = websocket_ ? hub_->websockets : hub_->sockets;
  --open;
  try {
    hub_->count([&](WebServerStats& s) { (websocket_ ? s.clients : s.connections) = static_cast<std::uint32_t>(open); });
  } catch (...) {
    // A mutex that fails to lock: the figure shown is stale, nothing else.
  }
}

// --- WebSocket --------------------------------------------------------------------------------

// A handshaken (or handshaking) WebSocket. At most one write in flight: its hello, replies in the
// order they came (at most kMaxReplies waiting), then the frame or snapshot of a tick that found it
// idle. A write not done within write_timeout_ms closes it.
class WsClient : public Connection, public std::enable_shared_from_this<WsClient> {
 public:
  WsClient(Hub& hub, Slot socket, beast::tcp_stream stream, bool may_control)
      : hub_(hub),
        connection_(hub.next_connection++),
        id_(hub.next_client++),
        socket_(std::move(socket)),
        client_slot_(hub, true),
        may_control_(may_control),
        ws_(std::move(stream)),
        read_buffer_(std::max<std::size_t>(hub.options.max_message_bytes, 1)),
        write_deadline_(hub.io) {}
  ~WsClient() override { hub_.connections.erase(connection_); }

  void start(http::request<http::string_body> request) {
    hub_.connections[connection_] = weak_from_this();
    request_ = std::move(request);
    // The WebSocket's own timers from here: the tcp_stream's would cut a connection that is only quiet.
    beast::get_lowest_layer(ws_).expires_never();
    websocket::stream_base::timeout timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.handshake_timeout = std::chrono::milliseconds(hub_.options.header_timeout_ms);
    timeouts.idle_timeout = kIdleTimeout;
    timeouts.keep_alive_pings = true;
    ws_.set_option(timeouts);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& response) { response.set(http::field::server, "stencil-display"); }));
    // Refused from the frame header, before anything is allocated for the payload.
    ws_.read_message_max(std::max<std::size_t>(hub_.options.max_message_bytes, 1));
    ws_.async_accept(request_, [self = shared_from_this()](error_code ec) { self->guarded([&] { self->on_accept(ec); }); });
  }

  void close() noexcept override {
    if (closed_) {
      return;
    }
    closed_ = true;
    hub_.clients.erase(id_);
    beast::get_lowest_layer(ws_).close();  // every pending operation ends, aborted
    try {
      write_deadline_.cancel();
    } catch (...) {
      // Its handler finds the client closed.
    }
  }

  // At a tick: the frame, or the snapshot when it needs one; dropped when it is still writing.
  void offer(const Message& frame, const Message& snapshot) {
    if (closed_ || !open_) {
      return;
    }
    if (writing_) {
      if (!need_snapshot_ && frame) {
        need_snapshot_ = true;  // it misses this frame: only a snapshot makes it whole again
        hub_.count([](WebServerStats& s) { ++s.frames_dropped; });
      }
      return;
    }
    if (need_snapshot_) {
      if (snapshot) {
        need_snapshot_ = false;
        hub_.count([](WebServerStats& s) { ++s.snapshots_sent; });
        write(snapshot);
      }
    } else if (frame) {
      write(frame);
    }
  }

  [[nodiscard]] bool wants_snapshot() const { return open_ && !closed_ && !writing_ && need_snapshot_; }

  void reply(std::string text) {
    if (closed_ || text.empty() || replies_.size() >= kMaxReplies) {
      return;
    }
    replies_.push_back(std::make_shared<const std::string>(std::move(text)));
    if (!writing_) {
      write_next_reply();
    }
  }

 private:
  // A handler's body: whatever it throws (no memory) closes this client, never the server.
  template <class Body>
  void guarded(Body&& body) noexcept {
    try {
      body();
    } catch (...) {
      close();
    }
  }

  void on_accept(error_code ec) {
    request_ = {};
    if (ec) {
      if (!closed_ && ec != net::error::operation_aborted) {
        hub_.count([](WebServerStats& s) { ++s.clients_dropped; });  // a handshake that timed out or was wrong
      }
      close();
      return;
    }
    if (closed_ || hub_.stopping) {
      close();
      return;
    }
    open_ = true;
    hub_.clients[id_] = shared_from_this();
    if (hub_.handlers.hello) {
      reply(hub_.handlers.hello(may_control_));
    }
    read();
  }

  void read() {
    ws_.async_read(read_buffer_, [self = shared_from_this()](error_code ec, std::size_t) {
      self->guarded([&] { self->on_read(ec); });
    });
  }

  void on_read(error_code ec) {
    if (ec) {
      if (ec == websocket::error::message_too_big || ec == websocket::error::buffer_overflow) {
        hub_.count([](WebServerStats& s) { ++s.malformed; });
      } else if (!closed_ && ec != websocket::error::closed && ec != net::error::eof &&
                 ec != net::error::operation_aborted) {
        hub_.count([](WebServerStats& s) { ++s.clients_dropped; });
      }
      close();
      return;
    }
    if (!ws_.got_text()) {
      hub_.count([](WebServerStats& s) { ++s.malformed; });
      reply(kNotText);
    } else {
      hub_.count([](WebServerStats& s) { ++s.messages_received; });
      const auto bytes = read_buffer_.data();
      const std::string_view text(static_cast<const char*>(bytes.data()), bytes.size());
      if (hub_.handlers.on_message) {
        reply(hub_.handlers.on_message(id_, may_control_, text));
      }
    }
    read_buffer_.consume(read_buffer_.size());
    if (!closed_) {
      read();
    }
  }

  void write_next_reply() {
    if (!replies_.empty()) {
      Message next = std::move(replies_.front());
      replies_.pop_front();
      write(next);
    }
  }

  // Called from the tick and from other clients' handlers too: it closes only this client on failure.
  void write(const Message& message) noexcept {
    guarded([&] { start_write(message); });
  }

  void start_write(const Message& message) {
    writing_ = true;
    write_deadline_.expires_after(std::chrono::milliseconds(hub_.options.write_timeout_ms));
    write_deadline_.async_wait([weak = weak_from_this()](error_code ec) {
      const auto self = weak.lock();
      if (ec || !self) {
        return;
      }
      // Expired, not re-armed by a later write: the client has taken too little for too long.
      self->guarded([&] {
        if (self->writing_ && self->write_deadline_.expiry() <= Clock::now() && !self->closed_) {
          self->hub_.count([](WebServerStats& s) { ++s.clients_dropped; });
          self->close();
        }
      });
    });
    ws_.text(true);
    ws_.async_write(net::buffer(*message), [self = shared_from_this(), message](error_code ec, std::size_t bytes) {
      self->guarded([&] { self->on_written(ec, bytes); });
    });
  }

  void on_written(error_code ec, std::size_t bytes) {
    writing_ = false;
    write_deadline_.cancel();  // throws only where no memory is left: guarded, it closes the client
    if (ec) {
      close();  // its read fails too, and says why
      return;
    }
    hub_.count([&](WebServerStats& s) {
      ++s.messages_sent;
      s.bytes_sent += bytes;
    });
    write_next_reply();
  }

  Hub& hub_;
  std::uint64_t connection_;
  ClientId id_;
  Slot socket_;
  Slot client_slot_;
  bool may_control_;
  websocket::stream<ClosingStream> ws_;
  beast::flat_buffer read_buffer_;
  net::steady_timer write_deadline_;
  http::request<http::string_body> request_;  // kept for the handshake's answer
  std::deque<Message> replies_;
  bool open_ = false;     // handshaken
  bool closed_ = false;
  bool writing_ = false;
  bool need_snapshot_ = true;  // new, or it missed a frame
};

// --- HTTP -------------------------------------------------------------------------------------

// A socket from accept to its one answer (no keep-alive), or to its WebSocket handshake.
class HttpSession : public Connection, public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Hub& hub, tcp::socket socket)
      : hub_(hub),
        connection_(hub.next_connection++),
        slot_(hub, false),
        stream_(std::move(socket)),
        buffer_(hub.options.header_limit_bytes + kMaxBodyBytes) {
    parser_.header_limit(static_cast<std::uint32_t>(std::min<std::size_t>(hub.options.header_limit_bytes, UINT32_MAX)));
    parser_.body_limit(kMaxBodyBytes);
  }
  ~HttpSession() override { hub_.connections.erase(connection_); }

  void start() {
    hub_.connections[connection_] = weak_from_this();
    // The whole request within the timeout, from accept: a slow-loris sender is cut off.
    stream_.expires_after(std::chrono::milliseconds(hub_.options.header_timeout_ms));
    http::async_read(stream_, buffer_, parser_, [self = shared_from_this()](error_code ec, std::size_t) {
      self->guarded([&] { self->on_read(ec); });
    });
  }

  void close() noexcept override {
    if (!upgraded_) {
      stream_.close();
    }
  }

 private:
  template <class Body>
  void guarded(Body&& body) noexcept {
    try {
      body();
    } catch (...) {
      close();
    }
  }

  void on_read(error_code ec) {
    if (ec == http::error::header_limit || ec == http::error::body_limit || ec == http::error::buffer_overflow) {
      respond(http::status::request_header_fields_too_large, "text/plain", "request too large\n");
      return;
    }
    if (ec) {
      // Timed out (a slow sender) or broken; a client that connected and went is not counted.
      if (ec != http::error::end_of_stream && ec != net::error::operation_aborted) {
        hub_.count([](WebServerStats& s) { ++s.clients_dropped; });
      }
      close();
      return;
    }
    if (hub_.stopping) {
      close();
      return;
    }
    const http::request<http::string_body>& request = parser_.get();
    head_ = request.method() == http::verb::head;
    if (request.method() != http::verb::get && !head_) {
      respond(http::status::method_not_allowed, "text/plain", "GET only\n");
      return;
    }
    if (websocket::is_upgrade(request)) {
      upgrade();
      return;
    }
    serve(path_of(request.target()));
  }

  void serve(std::string_view path) {
    if (path == "/api/part" || path == "/api/status") {
      const auto& document = path == "/api/part" ? hub_.handlers.part : hub_.handlers.status;
      body_ = document ? document() : std::string();
      if (body_.empty()) {
        respond(http::status::service_unavailable, "application/json", R"({"error":"not yet known"})");
        return;
      }
      answer(http::status::ok, "application/json", body_);
      return;
    }
    // Only the page's own files, by name: no path reaches the file system.
    const auto asset = hub_.assets.find(path == "/" ? std::string("index.html") : std::string(path.substr(1)));
    if (path.empty() || asset == hub_.assets.end()) {
      respond(http::status::not_found, "text/plain", "not found\n");
      return;
    }
    answer(http::status::ok, asset->second.type, asset->second.bytes);
  }

  // The WebSocket at /ws, only for this server's own page (an Origin naming it) and while there is
  // room; anything else is answered and closed.
  void upgrade() {
    const http::request<http::string_body>& request = parser_.get();
    const auto origin = request.find(http::field::origin);
    const bool ours = origin != request.end() && same_origin(origin->value(), request[http::field::host]);
    if (path_of(request.target()) != "/ws" || !ours) {
      hub_.count([](WebServerStats& s) { ++s.connections_refused; });
      respond(http::status::forbidden, "text/plain",
              path_of(request.target()) != "/ws" ? "no WebSocket here\n" : "this server's own page only\n");
      return;
    }
    if (hub_.websockets >= hub_.options.max_clients) {
      hub_.count([](WebServerStats& s) { ++s.connections_refused; });
      respond(http::status::service_unavailable, "text/plain", "too many displays open\n");
      return;
    }
    const bool control = may_control(hub_.options.token, query_value(request.target(), "token"));
    upgraded_ = true;
    stream_.expires_never();
    const auto client = std::make_shared<WsClient>(hub_, std::move(slot_), std::move(stream_), control);
    client->start(parser_.release());
  }

  // An answer with its own small body.
  void respond(http::status status, const char* type, std::string body) {
    body_ = std::move(body);
    answer(status, type, body_);
  }

  // `body` outlives the write: the session's own, or an asset held by the hub.
  void answer(http::status status, const std::string& type, const std::string& body) {
    response_.result(status);
    response_.version(11);
    response_.set(http::field::server, "stencil-display");
    response_.set(http::field::content_type, type);
    response_.set(http::field::cache_control, "no-store");
    response_.set("X-Content-Type-Options", "nosniff");
    response_.set("Content-Security-Policy", kSecurityPolicy);
    response_.set(http::field::connection, "close");
    response_.content_length(body.size());
    response_.body() = head_ ? http::span_body<const char>::value_type() : http::span_body<const char>::value_type(body.data(), body.size());
    stream_.expires_after(std::chrono::milliseconds(hub_.options.write_timeout_ms));
    http::async_write(stream_, response_, [self = shared_from_this()](error_code ec, std::size_t bytes) {
      self->guarded([&] { self->on_written(ec, bytes); });
    });
  }

  void on_written(error_code ec, std::size_t bytes) {
    if (!ec) {
      hub_.count([&](WebServerStats& s) { s.bytes_sent += bytes; });
      error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    }
    close();
  }

  Hub& hub_;
  std::uint64_t connection_;
  Slot slot_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request_parser<http::string_body> parser_;
  http::response<http::span_body<const char>> response_;
  std::string body_;
  bool head_ = false;
  bool upgraded_ = false;
};

// --- the hub ----------------------------------------------------------------------------------

void Hub::accept() {
  try {
    acceptor.async_accept([this](error_code ec, tcp::socket socket) { on_accept(ec, std::move(socket)); });
  } catch (...) {
    // No memory for the handler: try again later.
    accept_retry.expires_after(kAcceptRetry);
    accept_retry.async_wait([this](error_code ec) {
      if (!ec && !stopping) {
        accept();
      }
    });
  }
}

void Hub::on_accept(error_code ec, tcp::socket socket) {
  if (stopping || ec == net::error::operation_aborted) {
    return;
  }
  if (ec) {
    accept_retry.expires_after(kAcceptRetry);
    accept_retry.async_wait([this](error_code wait_ec) {
      if (!wait_ec && !stopping) {
        accept();
      }
    });
    return;
  }
  try {
    if (sockets >= options.max_connections) {
      count([](WebServerStats& s) { ++s.connections_refused; });
      error_code ignored;
      socket.close(ignored);  // at once: nothing is read or allocated for it
    } else {
      std::make_shared<HttpSession>(*this, std::move(socket))->start();
    }
  } catch (...) {
    // No memory for this one: it is closed as the socket goes; the others go on.
  }
  accept();
}

void Hub::schedule_tick() {
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options.frame_hz));
  next_tick += period;
  const auto now = Clock::now();
  if (next_tick < now) {
    next_tick = now + period;  // fell behind (a stalled host): skip, never burst
  }
  ticker.expires_at(next_tick);
  ticker.async_wait([this](error_code ec) {
    if (!ec && !stopping) {
      tick();
    }
  });
}

void Hub::tick() {
  try {
    schedule_tick();
  } catch (...) {
    return;  // no memory even for the timer's handler: the frames stop, the server does not
  }
  try {
    std::vector<std::shared_ptr<WsClient>> readers;
    readers.reserve(clients.size());
    bool snapshot_wanted = false;
    for (const auto& [id, client] : clients) {
      readers.push_back(client);
      snapshot_wanted = snapshot_wanted || client->wants_snapshot();
    }
    std::string frame_text, snapshot_text;
    if (handlers.tick) {
      handlers.tick(snapshot_wanted, frame_text, snapshot_text);
    }
    count([](WebServerStats& s) { ++s.ticks; });
    const Message frame = frame_text.empty() ? nullptr : std::make_shared<const std::string>(std::move(frame_text));
    const Message snapshot =
        snapshot_text.empty() ? nullptr : std::make_shared<const std::string>(std::move(snapshot_text));
    for (const auto& client : readers) {
      client->offer(frame, snapshot);
    }
  } catch (...) {
    // The display's tick threw (no memory): this frame is skipped.
  }
}

void Hub::send(ClientId client, std::string text) {
  const auto found = clients.find(client);
  if (found != clients.end()) {
    const std::shared_ptr<WsClient> alive = found->second;  // a failed write erases it from the table
    alive->reply(std::move(text));
  }
}

void Hub::shutdown() {
  stopping = true;
  error_code ignored;
  acceptor.close(ignored);
  ticker.cancel();
  accept_retry.cancel();
  // Copied first: closing one erases it from the tables.
  std::vector<std::shared_ptr<Connection>> open;
  for (const auto& [id, weak] : connections) {
    if (auto connection = weak.lock()) {
      open.push_back(std::move(connection));
    }
  }
  for (const auto& connection : open) {
    connection->close();
  }
  clients.clear();
}

}  // namespace

struct WebServer::Impl {
  Impl(const WebServerOptions& options, WebHandlers handlers) : hub(options, std::move(handlers)) {}  // NOLINT
  Hub hub;
  std::thread thread;
  int port = 0;
};

WebServer::WebServer(const WebServerOptions& options, WebHandlers handlers)
    : impl_(std::make_unique<Impl>(options, std::move(handlers))) {}

WebServer::~WebServer() { stop(); }

int WebServer::port() const { return impl_->port; }

std::string WebServer::url() const {
  return "http://" + host_text(impl_->hub.options.endpoint.host) + ":" + std::to_string(impl_->port) + "/";
}

bool WebServer::start(std::string& error) {
  Hub& hub = impl_->hub;
  const WebServerOptions& options = hub.options;
  if (impl_->thread.joinable()) {
    error = "the display's server is already running";
    return false;
  }
  if (!check_access(options.endpoint, options.token, error)) {
    return false;
  }
  if (!(options.frame_hz > 0.0) || options.max_clients < 1 || options.max_connections < 1 ||
      options.header_timeout_ms < 1 || options.write_timeout_ms < 1) {
    error = "the display's server: frame_hz, max_clients, max_connections and the timeouts must be positive";
    return false;
  }
  // Only the built page's own files are ever served: read once, here.
  std::error_code ec;
  const std::filesystem::path root(options.assets_dir);
  if (!std::filesystem::is_regular_file(root / "index.html", ec)) {
    error = "the display's page is not built: no " + (root / "index.html").string() +
            " (build it with cmake --build, which runs npm; or pass --assets DIR)";
    return false;
  }
  hub.assets.clear();
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    if (!entry.is_regular_file(ec) || entry.file_size(ec) > kMaxAssetBytes) {
      continue;
    }
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    const std::string name = entry.path().filename().string();
    hub.assets[name] = {content_type(name), bytes.str()};
  }
  const std::string listening = host_text(options.endpoint.host) + ":" + std::to_string(options.endpoint.port);
  const std::string host = options.endpoint.host == "localhost" ? "127.0.0.1" : options.endpoint.host;
  error_code bind_error;
  const net::ip::address address = net::ip::make_address(host, bind_error);
  if (bind_error) {
    error = "cannot listen on " + listening + ": " + bind_error.message();
    return false;
  }
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(options.endpoint.port));
  hub.acceptor.open(endpoint.protocol(), bind_error);
  if (!bind_error) {
    hub.acceptor.set_option(net::socket_base::reuse_address(true), bind_error);
  }
  if (!bind_error) {
    hub.acceptor.bind(endpoint, bind_error);
  }
  if (!bind_error) {
    hub.acceptor.listen(net::socket_base::max_listen_connections, bind_error);
  }
  if (bind_error) {
    error_code ignored;
    hub.acceptor.close(ignored);
    error = "cannot listen on " + listening + ": " + bind_error.message();
    return false;
  }
  impl_->port = hub.acceptor.local_endpoint(bind_error).port();
  hub.stopping = false;
  hub.io.restart();
  hub.next_tick = Clock::now();
  hub.accept();
  hub.schedule_tick();
  impl_->thread = std::thread([&hub] {
    // Every handler catches its own; this only keeps the loop alive should one ever escape.
    for (;;) {
      try {
        hub.io.run();
        return;
      } catch (...) {
      }
    }
  });
  return true;
}

void WebServer::stop() {
  if (!impl_->thread.joinable()) {
    return;
  }
  Hub& hub = impl_->hub;
  if (std::this_thread::get_id() == impl_->thread.get_id()) {
    hub.shutdown();  // from a handler: the thread ends when its handlers have; the destructor joins
    return;
  }
  // Closing every socket aborts each pending operation; the loop runs out of work and returns.
  net::post(hub.io, [&hub] { hub.shutdown(); });
  impl_->thread.join();
}

void WebServer::send(ClientId client, std::string text) { impl_->hub.send(client, std::move(text)); }

WebServerStats WebServer::stats() const {
  const std::lock_guard<std::mutex> lock(impl_->hub.stats_mutex);
  return impl_->hub.stats;
}

}  // namespace stencil::hmi
