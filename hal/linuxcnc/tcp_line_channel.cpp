// TcpLineChannel: see the header.
#include "hal/linuxcnc/tcp_line_channel.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace stencil::hal::linuxcnc {

TcpLineChannel::~TcpLineChannel() { close(); }

void TcpLineChannel::close() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
  fd_ = -1;
  start_ = 0;
  end_ = 0;
}

LineStatus TcpLineChannel::wait(short events, MonotonicNs deadline_ns) {
  for (;;) {
    const MonotonicNs left_ns = deadline_ns - clock_.now_ns();
    if (left_ns <= 0) {
      return LineStatus::Timeout;
    }
    pollfd p{fd_, events, 0};
    // Rounded up to the millisecond, so a wait never ends early and spins.
    const int ms = static_cast<int>(std::min<MonotonicNs>((left_ns + 999'999) / 1'000'000, 60'000));
    const int ready = ::poll(&p, 1, ms);
    if (ready < 0 && errno == EINTR) {
      continue;
    }
    if (ready < 0) {
      errno_ = errno;
      return LineStatus::Failed;
    }
    if (ready > 0) {
      return LineStatus::Ok;  // readable, writable, or an error the next call reports
    }
  }
}

LineStatus TcpLineChannel::connect(std::string_view ipv4, std::uint16_t port, MonotonicNs deadline_ns) {
  close();
  std::array<char, 16> address{};
  if (ipv4.size() >= address.size()) {
    errno_ = EINVAL;
    return LineStatus::Failed;
  }
  std::memcpy(address.data(), ipv4.data(), ipv4.size());
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.data(), &to.sin_addr) != 1) {
    errno_ = EINVAL;
    return LineStatus::Failed;
  }
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    errno_ = errno;
    return LineStatus::Failed;
  }
  const int one = 1;
  static_cast<void>(::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one));  // a line is a command: no Nagle
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0 && errno != EINPROGRESS) {
    errno_ = errno;
    close();
    return LineStatus::Failed;
  }
  const LineStatus ready = wait(POLLOUT, deadline_ns);
  if (ready != LineStatus::Ok) {
    close();
    return ready;
  }
  int error = 0;
  socklen_t size = sizeof error;
  if (::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &size) != 0 || error != 0) {
    errno_ = error != 0 ? error : errno;
    close();
    return LineStatus::Failed;
  }
  return LineStatus::Ok;
}

LineStatus TcpLineChannel::send_line(std::string_view line, MonotonicNs deadline_ns) {
  if (fd_ < 0) {
    return LineStatus::Closed;
  }
  std::array<char, kMaxLine + 2> bytes{};
  if (line.size() > kMaxLine) {
    return LineStatus::TooLong;
  }
  std::memcpy(bytes.data(), line.data(), line.size());
  bytes[line.size()] = '\r';
  bytes[line.size() + 1] = '\n';
  const std::size_t total = line.size() + 2;
  std::size_t sent = 0;
  while (sent < total) {
    const ssize_t n = ::send(fd_, bytes.data() + sent, total - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      bytes_sent_ += static_cast<std::uint64_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      const LineStatus ready = wait(POLLOUT, deadline_ns);
      if (ready != LineStatus::Ok) {
        return ready;
      }
      continue;
    }
    errno_ = errno;
    return errno == EPIPE || errno == ECONNRESET ? LineStatus::Closed : LineStatus::Failed;
  }
  return LineStatus::Ok;
}

LineStatus TcpLineChannel::read_line(std::string_view& line, MonotonicNs deadline_ns) {
  if (fd_ < 0) {
    return LineStatus::Closed;
  }
  for (;;) {
    // linuxcncrsh ends its lines "\r\n", a set's answer "\n\r" and a refused get's "\r\n\r\n": a
    // line is what lies between runs of line ends, and empty ones are none.
    while (start_ < end_ && (buffer_[start_] == '\r' || buffer_[start_] == '\n')) {
      ++start_;
    }
    // A whole line already here?
    for (std::size_t i = start_; i < end_; ++i) {
      if (buffer_[i] == '\n') {
        std::size_t length = i - start_;
        if (length > 0 && buffer_[start_ + length - 1] == '\r') {
          --length;
        }
        line = std::string_view(buffer_.data() + start_, length);
        start_ = i + 1;
        return LineStatus::Ok;
      }
    }
    if (start_ > 0) {  // keep the partial line at the front, room after it
      std::memmove(buffer_.data(), buffer_.data() + start_, end_ - start_);
      end_ -= start_;
      start_ = 0;
    }
    if (end_ == buffer_.size()) {
      return LineStatus::TooLong;
    }
    const ssize_t n = ::recv(fd_, buffer_.data() + end_, buffer_.size() - end_, 0);
    if (n > 0) {
      end_ += static_cast<std::size_t>(n);
      bytes_received_ += static_cast<std::uint64_t>(n);
      continue;
    }
    if (n == 0) {
      return LineStatus::Closed;
    }
    if (errno == EINTR) {
      continue;
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK) {
      const LineStatus ready = wait(POLLIN, deadline_ns);
      if (ready != LineStatus::Ok) {
        return ready;
      }
      continue;
    }
    errno_ = errno;
    return errno == ECONNRESET ? LineStatus::Closed : LineStatus::Failed;
  }
}

void TcpLineChannel::discard_pending() {
  start_ = 0;
  end_ = 0;
  if (fd_ < 0) {
    return;
  }
  std::array<char, 256> sink{};
  for (int i = 0; i < 64 && ::recv(fd_, sink.data(), sink.size(), MSG_DONTWAIT) > 0; ++i) {
  }  // bounded: a peer that keeps sending is found out by the next reply that does not parse
}

}  // namespace stencil::hal::linuxcnc
