#include "firmware/services/display_link/request_server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <vector>

#include "firmware/services/display_link/message_codec.hpp"

namespace stencil::display_link {
namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

bool fill_address(const std::string& path, sockaddr_un& address, std::string& error) {
  address = sockaddr_un{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof address.sun_path) {
    error = "the display socket's path '" + path + "' must be 1 to " + std::to_string(sizeof address.sun_path - 1) + " bytes";
    return false;
  }
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  return true;
}

}  // namespace

struct RequestServer::Peer {
  int fd = -1;
  bool welcomed = false;
  bool control = false;  // a control command's client (its Hello said so): its commands' source
  unsigned char buffer[kMessageBytes] = {};
  std::size_t filled = 0;
  double tokens = 0.0;
  double refilled_s = 0.0;
};

RequestServer::RequestServer(RequestServerOptions options, int feed_fd, Decide decide, control::CommandRing& commands)
    : options_(std::move(options)), feed_fd_(feed_fd), decide_(std::move(decide)), commands_(commands) {}

RequestServer::~RequestServer() { stop(); }

bool RequestServer::start(std::string& error) {
  sockaddr_un address{};
  if (!fill_address(options_.socket_path, address, error)) {
    return false;
  }
  struct stat existing {};
  if (lstat(options_.socket_path.c_str(), &existing) == 0) {
    if (!S_ISSOCK(existing.st_mode)) {
      error = options_.socket_path + " exists and is not a socket: not replaced";
      return false;
    }
    // A controller still behind it answers a connect: two controllers never share one socket.
    const int probe = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const bool live = probe >= 0 && connect(probe, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
    if (probe >= 0) {
      close(probe);
    }
    if (live) {
      error = options_.socket_path + ": another controller is serving displays there";
      return false;
    }
    unlink(options_.socket_path.c_str());  // left by a controller that died
  }
  listen_fd_ = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (listen_fd_ < 0) {
    error = std::string("the display socket: ") + std::strerror(errno);
    return false;
  }
  // Owner-only from the moment it exists (called before any of the job's threads run).
  const mode_t old_mask = umask(0177);
  const int bound = bind(listen_fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  const int bind_errno = errno;
  umask(old_mask);
  if (bound != 0 || listen(listen_fd_, 8) != 0) {
    error = options_.socket_path + ": " + std::strerror(bound != 0 ? bind_errno : errno);
    close(listen_fd_);
    listen_fd_ = -1;
    return false;
  }
  wake_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) {
    error = std::string("the display socket: eventfd: ") + std::strerror(errno);
    stop();
    return false;
  }
  stopping_.store(false);
  thread_ = std::thread([this] { serve(); });
  return true;
}

void RequestServer::stop() {
  stopping_.store(true);
  if (wake_fd_ >= 0) {
    const std::uint64_t one = 1;
    static_cast<void>(write(wake_fd_, &one, sizeof one));
  }
  if (thread_.joinable()) {
    thread_.join();
  }
  if (listen_fd_ >= 0) {
    close(listen_fd_);
    listen_fd_ = -1;
    unlink(options_.socket_path.c_str());
  }
  if (wake_fd_ >= 0) {
    close(wake_fd_);
    wake_fd_ = -1;
  }
}

RequestCounters RequestServer::counters() const {
  return RequestCounters{connected_.load(), seen_.load(),     accepted_.load(),     refused_.load(),
                         rate_limited_.load(), malformed_.load(), peers_refused_.load()};
}

void RequestServer::serve() {
  std::deque<Peer> peers;
  std::vector<pollfd> polled;
  while (!stopping_.load()) {
    polled.clear();
    polled.push_back({wake_fd_, POLLIN, 0});
    polled.push_back({listen_fd_, POLLIN, 0});
    for (const Peer& peer : peers) {
      polled.push_back({peer.fd, POLLIN, 0});
    }
    if (poll(polled.data(), polled.size(), 500) < 0 && errno != EINTR) {
      break;
    }
    if (stopping_.load()) {
      break;
    }
    // Peers first (their slots match polled[2...]), then new ones.
    for (std::size_t i = 0; i < peers.size();) {
      const short events = polled[i + 2].revents;
      if (events != 0 && !read_peer(peers[i])) {
        close(peers[i].fd);
        peers.erase(peers.begin() + static_cast<std::ptrdiff_t>(i));
        polled.erase(polled.begin() + static_cast<std::ptrdiff_t>(i + 2));
        connected_.store(peers.size());
        continue;
      }
      ++i;
    }
    if ((polled[1].revents & POLLIN) != 0) {
      accept_peers(peers);
    }
  }
  for (const Peer& peer : peers) {
    close(peer.fd);
  }
  connected_.store(0);
}

void RequestServer::accept_peers(std::deque<Peer>& peers) {
  for (;;) {
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) {
      return;  // EAGAIN: no more; anything else: try at the next wake
    }
    ucred credentials{};
    socklen_t length = sizeof credentials;
    const bool same_user = getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &credentials, &length) == 0 &&
                           (credentials.uid == geteuid() || credentials.uid == 0);
    if (!same_user || static_cast<int>(peers.size()) >= options_.max_displays) {
      close(fd);
      ++peers_refused_;
      continue;
    }
    Peer peer;
    peer.fd = fd;
    peer.tokens = options_.request_burst;
    peer.refilled_s = now_s();
    peers.push_back(peer);
    ++seen_;
    connected_.store(peers.size());
  }
}

bool RequestServer::read_peer(Peer& peer) {
  for (;;) {
    const ssize_t got = recv(peer.fd, peer.buffer + peer.filled, kMessageBytes - peer.filled, 0);
    if (got == 0) {
      return false;  // the display went away
    }
    if (got < 0) {
      return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    }
    peer.filled += static_cast<std::size_t>(got);
    if (peer.filled < kMessageBytes) {
      continue;
    }
    peer.filled = 0;
    Message message{};
    std::string error;
    const DecodeResult result = decode_request(peer.buffer, kMessageBytes, message, error);
    if (result == DecodeResult::VersionMismatch) {
      ++malformed_;
      Message mismatch = make_answer(MessageKind::Mismatch, message.id, error);
      static_cast<void>(answer(peer, mismatch, false));
      return false;
    }
    if (result != DecodeResult::Ok) {
      ++malformed_;  // a stream out of step cannot be trusted from here: closed
      static_cast<void>(answer(peer, make_answer(MessageKind::Refused, 0, "malformed: " + error), false));
      return false;
    }
    if (static_cast<MessageKind>(message.kind) == MessageKind::Hello) {
      peer.welcomed = true;
      peer.control = message.parameter == kHelloControl;
      if (!answer(peer, make_message(MessageKind::Welcome, message.id), true)) {
        return false;
      }
      continue;
    }
    if (!peer.welcomed) {
      ++malformed_;
      static_cast<void>(answer(peer, make_answer(MessageKind::Refused, message.id, "malformed: Hello first"), false));
      return false;
    }
    handle(peer, message);
    if (peer.fd < 0) {
      return false;
    }
  }
}

void RequestServer::handle(Peer& peer, const Message& message) {
  const double now = now_s();
  peer.tokens = std::min(options_.request_burst, peer.tokens + (now - peer.refilled_s) * options_.requests_per_s);
  peer.refilled_s = now;
  std::string refusal;
  const Request request = request_of(message);
  // A stop is never refused for coming too fast: it is what an operator presses again and again.
  if (request.kind != RequestKind::Stop && peer.tokens < 1.0) {
    ++rate_limited_;
    refusal = "too many requests: at most " + std::to_string(static_cast<int>(options_.requests_per_s)) + " a second";
  } else {
    peer.tokens = std::max(0.0, peer.tokens - 1.0);
    refusal = decide_ ? decide_(request) : std::string();
    control::Command command = command_of(request);
    if (peer.control) {
      command.source = control::CommandSource::Control;
    }
    // Straight into the cycle's ring: the next cycle takes it (this thread is the ring's one producer).
    // The last slot is kept for a stop; a stop pressed again within 100 ms of one already sent is the
    // same stop (accepted, not sent twice), so a held-down key fills neither the ring nor the record.
    const bool stop = request.kind == RequestKind::Stop;
    if (refusal.empty() && request.kind == RequestKind::Start) {
      // Taken by decide() itself (the program waiting to start the spindle): nothing for the cycle.
    } else if (refusal.empty() && stop && now - last_stop_s_ < 0.1) {
      ++stops_merged_;
    } else if (refusal.empty()) {
      const bool room = stop ? commands_.size() < control::CommandRing::capacity()
                             : commands_.size() + 1 < control::CommandRing::capacity();
      if (!room || !commands_.push(command)) {
        refusal = "too many requests waiting for the cycle; try again";
      } else if (stop) {
        last_stop_s_ = now;
      }
    }
    if (!refusal.empty()) {
      ++refused_;
    }
  }
  if (refusal.empty()) {
    ++accepted_;
  }
  const Message reply = refusal.empty() ? make_message(MessageKind::Accepted, message.id)
                                        : make_answer(MessageKind::Refused, message.id, refusal);
  if (!answer(peer, reply, false)) {
    close(peer.fd);
    peer.fd = -1;
  }
}

bool RequestServer::answer(Peer& peer, const Message& message, bool with_feed) {
  iovec part{const_cast<Message*>(&message), kMessageBytes};
  msghdr header{};
  header.msg_iov = &part;
  header.msg_iovlen = 1;
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(int))] = {};
  if (with_feed) {
    header.msg_control = control;
    header.msg_controllen = sizeof control;
    cmsghdr* descriptor = CMSG_FIRSTHDR(&header);
    descriptor->cmsg_level = SOL_SOCKET;
    descriptor->cmsg_type = SCM_RIGHTS;
    descriptor->cmsg_len = CMSG_LEN(sizeof(int));
    std::memcpy(CMSG_DATA(descriptor), &feed_fd_, sizeof(int));
  }
  // Never waits: a display whose socket is full is not reading, and is dropped.
  return sendmsg(peer.fd, &header, MSG_DONTWAIT | MSG_NOSIGNAL) == static_cast<ssize_t>(kMessageBytes);
}

}  // namespace stencil::display_link
