// TcpLineChannel: a text protocol's TCP connection, one line at a time, every call bounded by an
// absolute deadline on the link's Clock (non-blocking socket, poll). For linuxcncrsh: the machine
// thread's, not the 1 kHz cycle's; nothing allocates once constructed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/clock.hpp"

namespace stencil::hal::linuxcnc {

enum class LineStatus : std::uint8_t {
  Ok,
  Timeout,    // nothing complete by the deadline
  Closed,     // the peer closed the connection (or it was reset)
  TooLong,    // a line longer than the buffer: the connection can no longer be trusted
  Failed,     // a socket call failed (errno in last_errno())
};

class TcpLineChannel {
 public:
  static constexpr std::size_t kMaxLine = 1024;

  explicit TcpLineChannel(Clock& clock) : clock_(clock) {}
  ~TcpLineChannel();
  TcpLineChannel(const TcpLineChannel&) = delete;
  TcpLineChannel& operator=(const TcpLineChannel&) = delete;

  // Connects to an IPv4 address given as digits (no name lookup: it would allocate and may block
  // without bound) and port. Status Failed with last_errno() (ECONNREFUSED: nothing listens).
  LineStatus connect(std::string_view ipv4, std::uint16_t port, MonotonicNs deadline_ns);
  [[nodiscard]] bool is_open() const { return fd_ >= 0; }
  void close();

  // Sends `line` and a "\r\n" (whole, or a status that says why not).
  LineStatus send_line(std::string_view line, MonotonicNs deadline_ns);
  // The next non-empty line, without its end (any run of "\r" and "\n" ends a line); `line` stays
  // valid until the next call.
  LineStatus read_line(std::string_view& line, MonotonicNs deadline_ns);
  // Drops whatever has arrived and was not read (a reply that came after its deadline).
  void discard_pending();

  [[nodiscard]] int last_errno() const { return errno_; }
  [[nodiscard]] std::uint64_t bytes_sent() const { return bytes_sent_; }
  [[nodiscard]] std::uint64_t bytes_received() const { return bytes_received_; }

 private:
  // Waits for `events` on the socket until the deadline: true when ready.
  [[nodiscard]] LineStatus wait(short events, MonotonicNs deadline_ns);

  Clock& clock_;
  int fd_ = -1;
  int errno_ = 0;
  std::array<char, kMaxLine> buffer_{};  // bytes received, [start_, end_) not yet returned
  std::size_t start_ = 0;
  std::size_t end_ = 0;
  std::uint64_t bytes_sent_ = 0;
  std::uint64_t bytes_received_ = 0;
};

}  // namespace stencil::hal::linuxcnc
