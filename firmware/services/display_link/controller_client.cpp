#include "firmware/services/display_link/controller_client.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "firmware/services/display_link/message_codec.hpp"

namespace stencil::display_link {
namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

}  // namespace

const char* link_state_name(LinkState state) {
  switch (state) {
    case LinkState::Waiting:
      return "waiting";
    case LinkState::Connected:
      return "connected";
    case LinkState::Ended:
      return "ended";
    case LinkState::Refused:
      return "refused";
  }
  return "waiting";
}

ControllerClient::ControllerClient(std::string socket_path, bool control) : path_(std::move(socket_path)), control_(control) {
  detail_ = "no controller at " + path_ + " yet: waiting for one";
}

ControllerClient::~ControllerClient() {
  if (fd_ >= 0) {
    close(fd_);
  }
}

void ControllerClient::drop(LinkState state, const std::string& detail) {
  if (fd_ >= 0) {
    close(fd_);
    fd_ = -1;
  }
  welcomed_ = false;
  filled_ = 0;
  state_ = state;
  detail_ = detail;
}

void ControllerClient::try_connect() {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path_.empty() || path_.size() >= sizeof address.sun_path) {
    drop(LinkState::Refused, "the controller's socket path '" + path_ + "' is too long for a Unix socket");
    return;
  }
  std::memcpy(address.sun_path, path_.c_str(), path_.size() + 1);
  fd_ = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) {
    return;
  }
  // A Unix socket connects at once or not at all: no controller there yet keeps us waiting.
  if (connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int error = errno;
    close(fd_);
    fd_ = -1;
    if (state_ != LinkState::Ended && state_ != LinkState::Refused) {
      state_ = LinkState::Waiting;
      detail_ = "no controller at " + path_ + " (" + std::strerror(error) + "): waiting for one";
    }
    return;
  }
  Message hello = make_message(MessageKind::Hello, 0);
  hello.parameter = control_ ? kHelloControl : kHelloDisplay;
  if (::send(fd_, &hello, kMessageBytes, MSG_NOSIGNAL | MSG_DONTWAIT) != static_cast<ssize_t>(kMessageBytes)) {
    drop(state_, detail_);
  }
}

bool ControllerClient::send(const Message& message) {
  if (fd_ < 0 || !welcomed_) {
    return false;
  }
  if (::send(fd_, &message, kMessageBytes, MSG_NOSIGNAL | MSG_DONTWAIT) != static_cast<ssize_t>(kMessageBytes)) {
    drop(LinkState::Ended, "the controller stopped taking requests");
    return false;
  }
  return true;
}

void ControllerClient::poll(std::vector<Message>& answers, int retry_ms) {
  if (fd_ < 0) {
    const double now = now_s();
    if (now < next_try_s_) {
      return;
    }
    next_try_s_ = now + retry_ms / 1000.0;
    try_connect();
    if (fd_ < 0) {
      return;
    }
  }
  while (take(answers)) {
  }
}

// One message (and, with a Welcome, its descriptor); false when there is none now.
bool ControllerClient::take(std::vector<Message>& answers) {
  if (fd_ < 0) {
    return false;
  }
  iovec part{buffer_ + filled_, kMessageBytes - filled_};
  msghdr header{};
  header.msg_iov = &part;
  header.msg_iovlen = 1;
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(int))] = {};
  header.msg_control = control;
  header.msg_controllen = sizeof control;
  const ssize_t got = recvmsg(fd_, &header, MSG_DONTWAIT | MSG_CMSG_CLOEXEC);
  int passed_fd = -1;
  for (cmsghdr* c = CMSG_FIRSTHDR(&header); c != nullptr; c = CMSG_NXTHDR(&header, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS && c->cmsg_len == CMSG_LEN(sizeof(int))) {
      std::memcpy(&passed_fd, CMSG_DATA(c), sizeof(int));
    }
  }
  if (got == 0 || (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
    if (passed_fd >= 0) {
      close(passed_fd);
    }
    if (welcomed_) {
      drop(LinkState::Ended, "the controller ended");
    } else if (state_ != LinkState::Refused) {
      drop(state_ == LinkState::Ended ? LinkState::Ended : LinkState::Waiting, detail_);
    } else {
      drop(LinkState::Refused, detail_);
    }
    return false;
  }
  if (got < 0) {
    return false;
  }
  filled_ += static_cast<std::size_t>(got);
  if (filled_ < kMessageBytes) {
    if (passed_fd >= 0) {
      close(passed_fd);
    }
    return true;
  }
  filled_ = 0;
  Message message{};
  std::string error;
  const DecodeResult result = decode_message(buffer_, kMessageBytes, message, error);
  if (result != DecodeResult::Ok || static_cast<MessageKind>(message.kind) == MessageKind::Mismatch) {
    if (passed_fd >= 0) {
      close(passed_fd);
    }
    const std::string why = result == DecodeResult::Ok ? reason_of(message) : error;
    drop(LinkState::Refused, "the controller at " + path_ + " refused this display: " + why);
    return false;
  }
  if (static_cast<MessageKind>(message.kind) == MessageKind::Welcome) {
    if (passed_fd < 0) {
      drop(LinkState::Refused, "the controller's Welcome came without its state feed");
      return false;
    }
    auto feed = std::make_unique<FeedView>();
    if (!feed->open(passed_fd, error)) {
      drop(LinkState::Refused, error);
      return false;
    }
    feed_ = std::move(feed);
    ++generation_;
    welcomed_ = true;
    state_ = LinkState::Connected;
    detail_ = std::string(feed_->header().program) + " (pid " + std::to_string(feed_->header().controller_pid) + ") at " + path_;
    return true;
  }
  if (passed_fd >= 0) {
    close(passed_fd);
  }
  answers.push_back(message);
  return true;
}

}  // namespace stencil::display_link
