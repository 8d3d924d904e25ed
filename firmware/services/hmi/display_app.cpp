#include "firmware/services/hmi/display_app.hpp"

#include <cstdio>
#include <vector>

#include "firmware/services/display_link/message_codec.hpp"

namespace stencil::hmi {
namespace {

constexpr std::size_t kMaxPending = 64;  // requests the controller has not answered yet

const char* request_name(RequestKind kind) {
  switch (kind) {
    case RequestKind::Set:
      return "set";
    case RequestKind::Reset:
      return "reset";
    case RequestKind::Stop:
      return "stop";
    case RequestKind::Pause:
      return "pause";
    case RequestKind::Resume:
      return "resume";
    case RequestKind::Start:
      return "start";
  }
  return "unknown";
}

display_link::Message message_of(const Request& request, std::uint32_t id) {
  switch (request.kind) {
    case RequestKind::Set:
      return display_link::make_set(request.parameter, request.value, id);
    case RequestKind::Reset:
      return display_link::make_message(display_link::MessageKind::Reset, id);
    case RequestKind::Stop:
      return display_link::make_message(display_link::MessageKind::Stop, id);
    case RequestKind::Pause:
      return display_link::make_message(display_link::MessageKind::Pause, id);
    case RequestKind::Resume:
      return display_link::make_message(display_link::MessageKind::Resume, id);
    case RequestKind::Start:
      return display_link::make_message(display_link::MessageKind::Start, id);
  }
  return display_link::make_message(display_link::MessageKind::Stop, id);
}

nlohmann::json reply(const char* type, const Request* request, const std::string& detail) {
  nlohmann::json out{{"type", type}};
  if (request != nullptr) {
    out["request"] = request_name(request->kind);
    if (request->kind == RequestKind::Set) {
      out["name"] = control::parameter_name(command_kind(request->parameter));
      out["value"] = request->value;
    }
  }
  out[std::string(type) == "error" ? "error" : "reason"] = detail;
  return out;
}

}  // namespace

DisplayApp::DisplayApp(DisplayAppOptions options) : options_(std::move(options)), client_(options_.controller_socket) {
  WebHandlers handlers;
  handlers.tick = [this](bool wanted, std::string& frame, std::string& snapshot) { tick(wanted, frame, snapshot); };
  handlers.on_message = [this](ClientId client, bool may_control, std::string_view text) {
    return handle_message(client, may_control, text);
  };
  handlers.hello = [this](bool may_control) {
    nlohmann::json hello{{"type", "hello"},
                         {"may_control", may_control},
                         {"frame_hz", options_.web.frame_hz},
                         {"virtual_clock", state_.virtual_clock()}};
    if (!may_control) {
      hello["reason"] = "watch-only: open the page with ?token=... (the display's --token-file) to change anything";
    }
    return json_text(hello);
  };
  handlers.part = [this] { return state_.has_feed() ? state_.part_json() : std::string(); };
  handlers.status = [this] {
    nlohmann::json status = server_json();
    status["controller"] = display_link::link_state_name(client_.state());
    status["detail"] = client_.detail();
    status["coverage"] = state_.coverage();
    status["touched"] = state_.touched_count();
    status["frames"] = sequence_;
    return json_text(status);
  };
  web_ = std::make_unique<WebServer>(options_.web, std::move(handlers));
}

DisplayApp::~DisplayApp() { stop(); }

bool DisplayApp::start(std::string& error) { return web_->start(error); }

void DisplayApp::stop() { web_->stop(); }

DisplayCounters DisplayApp::counters() const {
  const std::lock_guard<std::mutex> lock(counters_mutex_);
  return counters_;
}

nlohmann::json DisplayApp::server_json() const {
  const WebServerStats s = web_->stats();
  const DisplayCounters c = counters();
  return {{"clients", s.clients},
          {"frames_dropped", s.frames_dropped},
          {"snapshots", s.snapshots_sent},
          {"malformed", s.malformed + c.malformed},
          {"refused", c.refused},
          {"accepted", c.accepted},
          {"connections_refused", s.connections_refused},
          {"clients_dropped", s.clients_dropped},
          {"bytes_sent", s.bytes_sent}};
}

std::string DisplayApp::handle_message(ClientId client, bool may_control, std::string_view text) {
  Request request;
  std::string error;
  if (!parse_request(text, request, error)) {
    const std::lock_guard<std::mutex> lock(counters_mutex_);
    ++counters_.malformed;
    return json_text(reply("error", nullptr, error));
  }
  std::string refused;
  if (!may_control) {
    refused = options_.web.token.empty() ? "this display is watch-only"
                                         : "this display is watch-only: open it with ?token=... to change anything";
  } else if (!state_.has_feed() || client_.state() != display_link::LinkState::Connected) {
    refused = "no controller to take it: " + client_.detail();
  } else if (request.kind == RequestKind::Set) {
    refused = refusal(request, state_.limits());
  } else if (request.kind == RequestKind::Reset) {
    refused = state_.reset_refusal();
  } else if (request.kind != RequestKind::Stop) {  // a stop always goes: the controller decides
    refused = state_.pause_refusal(request.kind);
  }
  if (refused.empty() && pending_.size() >= kMaxPending) {
    refused = "too many requests waiting for the controller; try again";
  }
  if (refused.empty()) {
    const std::uint32_t id = next_id_++;
    const display_link::Message message = message_of(request, id);
    if (client_.send(message)) {
      pending_[id] = Pending{client, request};
      const std::lock_guard<std::mutex> lock(counters_mutex_);
      ++counters_.forwarded;
      return "";
    }
    refused = "no controller to take it: " + client_.detail();
  }
  const std::lock_guard<std::mutex> lock(counters_mutex_);
  ++counters_.refused;
  return json_text(reply("refused", &request, refused));
}

void DisplayApp::take_answers() {
  std::vector<display_link::Message> answers;
  client_.poll(answers);
  for (const display_link::Message& answer : answers) {
    const auto found = pending_.find(answer.id);
    if (found == pending_.end()) {
      continue;
    }
    const Pending pending = found->second;
    pending_.erase(found);
    const bool accepted = static_cast<display_link::MessageKind>(answer.kind) == display_link::MessageKind::Accepted;
    {
      const std::lock_guard<std::mutex> lock(counters_mutex_);
      ++(accepted ? counters_.accepted : counters_.refused);
    }
    web_->send(pending.client,
               json_text(accepted ? reply("accepted", &pending.request, "passed to the cycle; its outcome comes in the frames' params")
                                : reply("refused", &pending.request, display_link::reason_of(answer))));
  }
  if (client_.state() != display_link::LinkState::Connected && !pending_.empty()) {
    for (const auto& [id, pending] : pending_) {
      web_->send(pending.client, json_text(reply("refused", &pending.request, "the controller went away before answering")));
    }
    pending_.clear();
  }
}

void DisplayApp::tick(bool snapshot_wanted, std::string& frame, std::string& snapshot) {
  take_answers();
  const display_link::LinkState link = client_.state();
  state_.set_link(link, client_.detail());
  if (!options_.quiet && (link != shown_ || !said_)) {
    std::printf("display: controller %s: %s\n", display_link::link_state_name(link), client_.detail().c_str());
    std::fflush(stdout);
    shown_ = link;
    said_ = true;
  }
  state_.update(client_.feed(), client_.feed_generation());
  ++sequence_;
  const nlohmann::json server = server_json();
  frame = json_text(state_.frame(sequence_, server));
  if (snapshot_wanted) {
    snapshot = json_text(state_.snapshot(sequence_, server));
  }
}

}  // namespace stencil::hmi
