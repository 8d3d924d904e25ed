#include "firmware/services/hmi/hmi_server.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <civetweb.h>

namespace stencil::hmi {
namespace {

constexpr std::uintmax_t kMaxAssetBytes = 16u << 20;  // each file
constexpr std::size_t kMaxReplies = 8;                 // waiting per client; more are dropped
constexpr std::size_t kMaxCommands = 16;               // waiting for the command ring

const char* content_type(const std::string& path) {
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

void send_response(mg_connection* conn, int status, const char* reason, const char* type, const std::string& body,
                   bool head) {
  mg_printf(conn,
            "HTTP/1.1 %d %s\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-store\r\n"
            "X-Content-Type-Options: nosniff\r\n"
            "Content-Security-Policy: default-src 'self'; connect-src 'self' ws: wss:; img-src 'self' data:\r\n"
            "Connection: close\r\n\r\n",
            status, reason, type, body.size());
  if (!head && !body.empty()) {
    mg_write(conn, body.data(), body.size());
  }
}

nlohmann::json reply(const char* type, const Request* request, const std::string& detail) {
  nlohmann::json out{{"type", type}};
  if (request != nullptr) {
    out["request"] = request->kind == RequestKind::Reset ? "reset" : "set";
    if (request->kind == RequestKind::Set) {
      out["name"] = control::parameter_name(command_kind(request->parameter));
      out["value"] = request->value;
    }
  }
  out[std::string(type) == "error" ? "error" : "reason"] = detail;
  return out;
}

// Serialised without ever throwing: text from a client (quoted back in an error) may not be valid
// UTF-8, and an exception must never leave a civetweb callback.
std::string text_of(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

struct HmiServer::Client {
  mg_connection* conn = nullptr;
  bool may_control = false;
  std::mutex mutex;
  std::condition_variable wake;
  std::string pending;               // the next frame or snapshot; empty: none
  std::deque<std::string> replies;   // answers to its requests, sent before the next frame
  bool need_snapshot = true;         // new, or it missed a frame
  bool closed = false;
  std::thread sender;
  std::once_flag joined;
};

HmiLimits limits_of(const control::ControllerConfig& config) {
  HmiLimits limits;
  limits.board_force_limit_n = config.haptic.max_force_n;
  limits.mill_speed_mm_per_s = std::min(config.max_axis_move_mm, config.max_total_move_mm) / config.period_s;
  limits.min_coupling_n_per_device_mm = config.min_coupling_n_per_device_mm;
  limits.max_coupling_n_per_device_mm = config.max_coupling_n_per_device_mm;
  return limits;
}

HmiServer::HmiServer(const HmiServerOptions& options, const tables::PartTables& part,
                     const control::ControllerConfig& config)
    : options_(options), limits_(limits_of(config)), state_(part, config, limits_) {}

HmiServer::~HmiServer() { stop(); }

std::string HmiServer::url() const {
  const bool v6 = options_.endpoint.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + options_.endpoint.host + "]" : options_.endpoint.host) + ":" + std::to_string(port_) + "/";
}

bool HmiServer::start(std::string& error) {
  if (!check_access(options_.endpoint, options_.token, error)) {
    return false;
  }
  // Only the built page's own files are ever served: read once, here.
  std::error_code ec;
  const std::filesystem::path root(options_.assets_dir);
  if (!std::filesystem::is_regular_file(root / "index.html", ec)) {
    error = "the display's page is not built: no " + (root / "index.html").string() +
            " (build it with cmake --build, which runs npm; or pass --hmi-assets DIR)";
    return false;
  }
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    if (!entry.is_regular_file(ec) || entry.file_size(ec) > kMaxAssetBytes) {
      continue;
    }
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    const std::string name = entry.path().filename().string();
    assets_[name] = {content_type(name), bytes.str()};
  }
  {
    const std::lock_guard<std::mutex> lock(state_mutex_);
    part_json_ = text_of(state_.part_mesh());
  }
  const bool v6 = options_.endpoint.host.find(':') != std::string::npos;
  const std::string listening = (v6 ? "[" + options_.endpoint.host + "]" : options_.endpoint.host) + ":" +
                                std::to_string(options_.endpoint.port);
  const std::string threads = std::to_string(options_.max_clients + 4);  // a WebSocket holds a worker each
  const std::string timeout = std::to_string(options_.write_timeout_ms);
  const char* civet_options[] = {"listening_ports", listening.c_str(),
                                 "num_threads", threads.c_str(),
                                 "request_timeout_ms", timeout.c_str(),
                                 "websocket_timeout_ms", "30000",
                                 "enable_websocket_ping_pong", "yes",
                                 "max_request_size", "8192",
                                 "enable_directory_listing", "no",
                                 "enable_keep_alive", "no",
                                 nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };  // no stray lines on the terminal
  mg_init_library(0);
  char init_error[256] = {};
  mg_init_data init{&callbacks, this, civet_options};
  mg_error_data error_data{};
  error_data.text = init_error;
  error_data.text_buffer_size = sizeof init_error;
  context_ = mg_start2(&init, &error_data);
  if (context_ == nullptr) {
    error = "--hmi " + listening + ": cannot listen: " + (init_error[0] != '\0' ? init_error : "unknown error");
    return false;
  }
  mg_server_port ports[4] = {};
  if (mg_get_server_ports(context_, 4, ports) > 0) {
    port_ = ports[0].port;
  }
  mg_set_request_handler(context_, "/", &HmiServer::on_http, this);
  mg_set_websocket_handler(context_, "/ws", &HmiServer::on_ws_connect, &HmiServer::on_ws_ready, &HmiServer::on_ws_data,
                           &HmiServer::on_ws_close, this);
  stopping_.store(false);
  frame_thread_ = std::thread([this] { frame_loop(); });
  return true;
}

void HmiServer::stop() {
  if (context_ == nullptr) {
    return;
  }
  {
    const std::lock_guard<std::mutex> lock(frame_mutex_);
    stopping_.store(true);
  }
  frame_wake_.notify_all();
  if (frame_thread_.joinable()) {
    frame_thread_.join();
  }
  // Every sender takes nothing more; then civetweb stops: its stop flag ends any write in progress,
  // and each connection's close handler joins its sender. Any sender left is joined after.
  std::vector<std::shared_ptr<Client>> clients;
  {
    const std::lock_guard<std::mutex> lock(clients_mutex_);
    clients = clients_;
  }
  for (const auto& client : clients) {
    {
      const std::lock_guard<std::mutex> lock(client->mutex);
      client->closed = true;
    }
    client->wake.notify_all();
  }
  mg_stop(context_);
  context_ = nullptr;
  for (const auto& client : clients) {
    std::call_once(client->joined, [&] {
      if (client->sender.joinable()) {
        client->sender.join();
      }
    });
  }
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  clients_.clear();
}

void HmiServer::on_record(const control::JournalRecord& record) {
  const std::lock_guard<std::mutex> lock(state_mutex_);
  state_.on_record(record);
}

void HmiServer::on_telemetry(const control::Telemetry& telemetry) {
  const std::lock_guard<std::mutex> lock(state_mutex_);
  state_.on_telemetry(telemetry);
}

void HmiServer::on_machine(double lag_mm, const control::CommandedStock& model) {
  const std::lock_guard<std::mutex> machine_lock(machine_mutex_);
  const std::int64_t now_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  if (last_machine_ns_ != 0 && now_ns - last_machine_ns_ < 100'000'000) {
    return;
  }
  last_machine_ns_ = now_ns;
  on_stock(lag_mm, coarse_stock(model));  // sampled on the caller's thread, which owns the model
}

void HmiServer::on_stock(double lag_mm, StockGrid stock) {
  const std::lock_guard<std::mutex> lock(state_mutex_);
  state_.on_machine(lag_mm, std::move(stock));
}

void HmiServer::seed_touched(const engine::TriangleSet& touched) {
  const std::lock_guard<std::mutex> lock(state_mutex_);
  state_.seed_touched(touched);
}

bool HmiServer::pop_command(control::Command& command) {
  const std::lock_guard<std::mutex> lock(state_mutex_);
  if (commands_.empty()) {
    return false;
  }
  command = commands_.front();
  commands_.pop_front();
  return true;
}

HmiServerStats HmiServer::stats() const {
  HmiServerStats out;
  {
    const std::lock_guard<std::mutex> lock(stats_mutex_);
    out = stats_;
  }
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  out.clients = static_cast<std::uint32_t>(clients_.size());
  return out;
}

nlohmann::json HmiServer::server_json() const {
  const HmiServerStats s = stats();
  return {{"clients", s.clients},   {"frames_dropped", s.frames_dropped}, {"snapshots", s.snapshots_sent},
          {"malformed", s.malformed}, {"refused", s.refused},             {"accepted", s.accepted},
          {"bytes_sent", s.bytes_sent}};
}

std::string HmiServer::handle_message(bool may_control, std::string_view text) {
  Request request;
  std::string error;
  if (!parse_request(text, request, error)) {
    const std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.malformed;
    return text_of(reply("error", nullptr, error));
  }
  std::string refused;
  if (!may_control) {
    refused = options_.token.empty() ? "this display is watch-only"
                                     : "this display is watch-only: open it with ?token=... (--hmi-token) to change anything";
  } else {
    const std::lock_guard<std::mutex> lock(state_mutex_);
    if (request.kind == RequestKind::Set) {
      refused = refusal(request, limits_);
    } else {
      refused = state_.reset_refusal();
    }
    if (refused.empty()) {
      if (commands_.size() >= kMaxCommands) {
        refused = "too many requests waiting for the cycle; try again";
      } else {
        commands_.push_back(request.kind == RequestKind::Reset ? control::Command{control::CommandKind::Reset, 0.0}
                                                                : control::Command{command_kind(request.parameter), request.value});
      }
    }
  }
  const std::lock_guard<std::mutex> lock(stats_mutex_);
  if (!refused.empty()) {
    ++stats_.refused;
    return text_of(reply("refused", &request, refused));
  }
  ++stats_.accepted;
  return text_of(reply("accepted", &request, "passed to the cycle; its outcome comes in the frames' params"));
}

int HmiServer::on_http(mg_connection* conn, void* self_pointer) {
  try {
    return serve_http(conn, *static_cast<HmiServer*>(self_pointer));
  } catch (...) {
    return 500;  // civetweb answers it; the server goes on
  }
}

int HmiServer::serve_http(mg_connection* conn, HmiServer& self) {
  const mg_request_info* info = mg_get_request_info(conn);
  const std::string method = info->request_method != nullptr ? info->request_method : "";
  const bool head = method == "HEAD";
  if (method != "GET" && !head) {
    send_response(conn, 405, "Method Not Allowed", "text/plain", "GET only\n", false);
    return 405;
  }
  std::string uri = info->local_uri != nullptr ? info->local_uri : "/";
  if (uri == "/api/part") {
    send_response(conn, 200, "OK", "application/json", self.part_json_, head);
    return 200;
  }
  if (uri == "/api/status") {
    nlohmann::json status = self.server_json();
    {
      const std::lock_guard<std::mutex> lock(self.state_mutex_);
      status["coverage"] = self.state_.coverage();
      status["touched"] = self.state_.touched_count();
      status["frames"] = self.sequence_;
    }
    send_response(conn, 200, "OK", "application/json", text_of(status), head);
    return 200;
  }
  if (uri == "/") {
    uri = "/index.html";
  }
  const auto asset = self.assets_.find(uri.substr(1));
  if (asset == self.assets_.end()) {
    send_response(conn, 404, "Not Found", "text/plain", "not found\n", head);
    return 404;
  }
  send_response(conn, 200, "OK", asset->second.first.c_str(), asset->second.second, head);
  return 200;
}

int HmiServer::on_ws_connect(const mg_connection* conn, void* self_pointer) {
  auto& self = *static_cast<HmiServer*>(self_pointer);
  try {
    // A browser says which page opened the socket: another site's page (open in the operator's
    // browser) must not reach the controller through it.
    const char* origin = mg_get_header(conn, "Origin");
    const char* host = mg_get_header(conn, "Host");
    const bool foreign = origin != nullptr && !same_origin(origin, host != nullptr ? host : "");
    // Admission counts connected clients only: a handshake that fails after this is never counted.
    const std::lock_guard<std::mutex> lock(self.clients_mutex_);
    if (self.stopping_.load() || foreign || static_cast<int>(self.clients_.size()) >= self.options_.max_clients) {
      const std::lock_guard<std::mutex> stats_lock(self.stats_mutex_);
      ++self.stats_.connections_refused;
      return 1;  // refused before the handshake
    }
    return 0;
  } catch (...) {
    return 1;
  }
}

void HmiServer::on_ws_ready(mg_connection* conn, void* self_pointer) {
  auto& self = *static_cast<HmiServer*>(self_pointer);
  try {
    auto client = std::make_shared<Client>();
    client->conn = conn;
    const mg_request_info* info = mg_get_request_info(conn);
    char token[256] = {};
    const char* query = info->query_string != nullptr ? info->query_string : "";
    const int length = mg_get_var(query, std::strlen(query), "token", token, sizeof token);
    client->may_control = may_control(self.options_.token, length > 0 ? std::string_view(token, static_cast<std::size_t>(length))
                                                                      : std::string_view());
    nlohmann::json hello{{"type", "hello"},
                         {"may_control", client->may_control},
                         {"frame_hz", self.options_.frame_hz},
                         {"virtual_clock", self.options_.virtual_clock}};
    if (!client->may_control) {
      hello["reason"] = "watch-only: open the page with ?token=... (--hmi-token) to change anything";
    }
    client->replies.push_back(text_of(hello));
    // The sender first, then the client made visible: stop() and the close handler only ever see a
    // client whose sender exists.
    client->sender = std::thread([&self, client] { self.send_loop(client); });
    mg_set_user_connection_data(conn, new std::shared_ptr<Client>(client));
    const std::lock_guard<std::mutex> lock(self.clients_mutex_);
    self.clients_.push_back(client);
  } catch (...) {
    // No thread or no memory: this client gets nothing; civetweb closes it when it next reads.
  }
}

int HmiServer::on_ws_data(mg_connection* conn, int bits, char* data, std::size_t length, void* self_pointer) {
  auto& self = *static_cast<HmiServer*>(self_pointer);
  try {
    auto* holder = static_cast<std::shared_ptr<Client>*>(mg_get_user_connection_data(conn));
    if (holder == nullptr) {
      return 0;
    }
    const std::shared_ptr<Client>& client = *holder;
    const int opcode = bits & 0x0F;
    if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) {
      return 0;
    }
    if (opcode == MG_WEBSOCKET_OPCODE_PING || opcode == MG_WEBSOCKET_OPCODE_PONG) {
      return 1;
    }
    std::string answer;
    bool keep = true;
    if (opcode != MG_WEBSOCKET_OPCODE_TEXT || (bits & 0x80) == 0) {
      const std::lock_guard<std::mutex> lock(self.stats_mutex_);
      ++self.stats_.malformed;
      answer = text_of(reply("error", nullptr, "expected one unfragmented text frame of JSON"));
    } else if (length > kMaxRequestBytes) {
      const std::lock_guard<std::mutex> lock(self.stats_mutex_);
      ++self.stats_.malformed;
      answer = text_of(reply("error", nullptr, "message of " + std::to_string(length) + " bytes: at most " +
                                                   std::to_string(kMaxRequestBytes) + "; closing"));
      keep = false;
    } else {
      answer = self.handle_message(client->may_control, std::string_view(data, length));
    }
    {
      const std::lock_guard<std::mutex> lock(client->mutex);
      if (client->replies.size() < kMaxReplies) {
        client->replies.push_back(std::move(answer));
      }
    }
    client->wake.notify_all();
    return keep ? 1 : 0;
  } catch (...) {
    return 0;  // closes this connection; the server and the job go on
  }
}

void HmiServer::on_ws_close(const mg_connection* conn, void* self_pointer) {
  auto& self = *static_cast<HmiServer*>(self_pointer);
  auto* holder = static_cast<std::shared_ptr<Client>*>(mg_get_user_connection_data(conn));
  if (holder == nullptr) {
    return;  // refused, or never ready
  }
  std::shared_ptr<Client> client = *holder;
  delete holder;
  mg_set_user_connection_data(conn, nullptr);
  {
    const std::lock_guard<std::mutex> lock(client->mutex);
    client->closed = true;
  }
  client->wake.notify_all();
  // Its sender may be in a write: civetweb's stop flag (at stop()) or the write timeout ends it.
  std::call_once(client->joined, [&] {
    if (client->sender.joinable()) {
      client->sender.join();
    }
  });
  const std::lock_guard<std::mutex> lock(self.clients_mutex_);
  std::erase(self.clients_, client);
}

void HmiServer::send_loop(const std::shared_ptr<Client>& client) {
  try {
    send_messages(client);
  } catch (...) {
    const std::lock_guard<std::mutex> lock(client->mutex);
    client->closed = true;  // out of memory: this client gets nothing more
  }
}

void HmiServer::send_messages(const std::shared_ptr<Client>& client) {
  for (;;) {
    std::string message;
    {
      std::unique_lock<std::mutex> lock(client->mutex);
      client->wake.wait(lock, [&] { return client->closed || !client->replies.empty() || !client->pending.empty(); });
      if (client->closed) {
        return;
      }
      if (!client->replies.empty()) {
        message = std::move(client->replies.front());
        client->replies.pop_front();
      } else {
        message = std::move(client->pending);
        client->pending.clear();
      }
    }
    // Blocks while the client's socket is full, at most the write timeout (civetweb's request
    // timeout); a client that took nothing for that long is dropped.
    const int written = mg_websocket_write(client->conn, MG_WEBSOCKET_OPCODE_TEXT, message.data(), message.size());
    const std::lock_guard<std::mutex> lock(stats_mutex_);
    // Short: the write timed out part way, and the client's stream is broken from here.
    if (written <= 0 || static_cast<std::size_t>(written) < message.size()) {
      ++stats_.clients_dropped;
      const std::lock_guard<std::mutex> client_lock(client->mutex);
      client->closed = true;  // nothing more is sent; civetweb closes it on its side
      return;
    }
    ++stats_.messages_sent;
    stats_.bytes_sent += message.size();
  }
}

void HmiServer::frame_loop() {
  try {
    build_frames();
  } catch (...) {
    // Out of memory building a frame: the display stops updating (its clients see no frames and
    // say so); the job goes on.
  }
}

void HmiServer::build_frames() {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / options_.frame_hz));
  auto next = std::chrono::steady_clock::now() + period;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(frame_mutex_);
      if (frame_wake_.wait_until(lock, next, [&] { return stopping_.load(); })) {
        return;
      }
    }
    next += period;
    const auto now = std::chrono::steady_clock::now();
    if (next < now) {
      next = now + period;  // fell behind (a stalled host): skip, never burst
    }
    std::vector<std::shared_ptr<Client>> clients;
    {
      const std::lock_guard<std::mutex> lock(clients_mutex_);
      clients = clients_;
    }
    bool want_snapshot = false;
    for (const auto& client : clients) {
      const std::lock_guard<std::mutex> lock(client->mutex);
      want_snapshot = want_snapshot || (!client->closed && (client->need_snapshot || !client->pending.empty()));
    }
    const nlohmann::json server = server_json();
    nlohmann::json frame_json, snapshot_json;
    {
      const std::lock_guard<std::mutex> lock(state_mutex_);
      ++sequence_;
      frame_json = state_.frame(sequence_, server);
      if (want_snapshot) {
        snapshot_json = state_.snapshot(sequence_, server);
      }
    }
    // Serialised outside the lock: the feeding threads wait only for the state's copy.
    const std::string frame = text_of(frame_json);
    const std::string snapshot = want_snapshot ? text_of(snapshot_json) : std::string();
    std::uint64_t dropped = 0, snapshots = 0;
    for (const auto& client : clients) {
      {
        const std::lock_guard<std::mutex> lock(client->mutex);
        if (client->closed) {
          continue;
        }
        if (!client->pending.empty()) {
          ++dropped;  // it has not taken the last one yet: it gets a snapshot once it has
          client->need_snapshot = true;
          continue;
        }
        if (client->need_snapshot) {
          client->pending = snapshot;
          client->need_snapshot = false;
          ++snapshots;
        } else {
          client->pending = frame;
        }
      }
      client->wake.notify_all();
    }
    const std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.frames;
    stats_.frames_dropped += dropped;
    stats_.snapshots_sent += snapshots;
  }
}

}  // namespace stencil::hmi
