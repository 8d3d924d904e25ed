// A display's end of the link to one controller: the request socket, connected (and connected again
// after the controller ends, for the next job on the same socket) without ever blocking the caller,
// and the state feed the controller hands over, mapped read-only. Driven by the display's tick.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "firmware/services/display_link/display_wire.hpp"
#include "firmware/services/display_link/state_feed.hpp"

namespace stencil::display_link {

enum class LinkState : std::uint8_t {
  Waiting,    // no controller yet (or none since the last one ended)
  Connected,  // welcomed: the feed is live
  Ended,      // the controller went away; the feed shows its last state
  Refused,    // it speaks another protocol version, or refused us
};
[[nodiscard]] const char* link_state_name(LinkState state);  // "waiting", "connected", "ended", "refused"

class ControllerClient {
 public:
  // `control`: a control command's client (stencil-rig stop, ...), whose requests the controller
  // records as from `control`; else a display.
  explicit ControllerClient(std::string socket_path, bool control = false);
  ~ControllerClient();
  ControllerClient(const ControllerClient&) = delete;
  ControllerClient& operator=(const ControllerClient&) = delete;

  // Connects when not connected (at most every `retry_ms`), takes the Welcome and its feed, and
  // hands back the controller's answers to our requests. Never blocks.
  void poll(std::vector<Message>& answers, int retry_ms = 250);

  // Sends a Set or Reset (numbered by the caller); false when there is no controller to take it.
  [[nodiscard]] bool send(const Message& message);

  [[nodiscard]] LinkState state() const { return state_; }
  [[nodiscard]] const std::string& detail() const { return detail_; }  // what the state means, for people
  // The newest controller's feed (still there after it ended); null before any.
  [[nodiscard]] const FeedView* feed() const { return feed_ && feed_->is_open() ? feed_.get() : nullptr; }
  // Counts up each time a new feed is mapped (a new controller, a new job).
  [[nodiscard]] std::uint64_t feed_generation() const { return generation_; }
  [[nodiscard]] const std::string& socket_path() const { return path_; }

 private:
  void try_connect();
  void drop(LinkState state, const std::string& detail);
  bool take(std::vector<Message>& answers);

  std::string path_;
  bool control_ = false;
  int fd_ = -1;
  bool welcomed_ = false;
  LinkState state_ = LinkState::Waiting;
  std::string detail_;
  std::unique_ptr<FeedView> feed_;
  std::uint64_t generation_ = 0;
  unsigned char buffer_[kMessageBytes] = {};
  std::size_t filled_ = 0;
  double next_try_s_ = 0.0;
};

}  // namespace stencil::display_link
