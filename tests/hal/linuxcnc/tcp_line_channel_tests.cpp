// The TCP line channel against a listening socket the test owns on loopback: lines both ways, the
// "\n\r" linuxcncrsh ends a set's answer with and the empty line after a refused get, a peer that says nothing (a timeout by the
// deadline), one that hangs up, one that sends a line longer than the buffer, and nothing listening.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <string_view>

#include "hal/linuxcnc/tcp_line_channel.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::hal;
using namespace stencil::hal::linuxcnc;

namespace {

constexpr MonotonicNs kMs = 1'000'000;

// A listening socket on 127.0.0.1 at a port the kernel picks.
struct Listener {
  int fd = -1;
  std::uint16_t port = 0;
  Listener() {
    fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in at{};
    at.sin_family = AF_INET;
    at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    CHECK_EQUAL(0, ::bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof at));
    CHECK_EQUAL(0, ::listen(fd, 4));
    socklen_t size = sizeof at;
    CHECK_EQUAL(0, ::getsockname(fd, reinterpret_cast<sockaddr*>(&at), &size));
    port = ntohs(at.sin_port);
  }
  ~Listener() { ::close(fd); }
  int accept_one() const { return ::accept(fd, nullptr, nullptr); }
};

void write_all(int fd, std::string_view bytes) {
  CHECK_EQUAL(static_cast<ssize_t>(bytes.size()), ::write(fd, bytes.data(), bytes.size()));
}

std::string read_some(int fd) {
  char buffer[256];
  const ssize_t n = ::read(fd, buffer, sizeof buffer);
  return n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : std::string();
}

}  // namespace

TEST_GROUP(TcpLineChannel) {
  posix_clock::MonotonicClock clock;
  MonotonicNs in(MonotonicNs ns) { return clock.now_ns() + ns; }
};

TEST(TcpLineChannel, LinesGoOutWithCrLfAndComeBackWithoutTheirEnds) {
  Listener listener;
  TcpLineChannel channel(clock);
  CHECK(channel.connect("127.0.0.1", listener.port, in(500 * kMs)) == LineStatus::Ok);
  const int peer = listener.accept_one();
  CHECK(channel.send_line("get estop", in(500 * kMs)) == LineStatus::Ok);
  STRCMP_EQUAL("get estop\r\n", read_some(peer).c_str());
  // linuxcncrsh ends a set's answer "\n\r": the "\r" must not start the next line.
  write_all(peer, "SET MDI ACK\n\rGET FOO NAK\r\n\r\nESTOP OFF\r\nHELLO");
  std::string_view line;
  CHECK(channel.read_line(line, in(500 * kMs)) == LineStatus::Ok);
  CHECK(line == "SET MDI ACK");
  CHECK(channel.read_line(line, in(500 * kMs)) == LineStatus::Ok);
  CHECK(line == "GET FOO NAK");  // and its extra empty line is none
  CHECK(channel.read_line(line, in(500 * kMs)) == LineStatus::Ok);
  CHECK(line == "ESTOP OFF");
  // Half a line is not a line: it waits for the rest, until the deadline.
  CHECK(channel.read_line(line, in(30 * kMs)) == LineStatus::Timeout);
  write_all(peer, " ACK X 1.1\r\n");
  CHECK(channel.read_line(line, in(500 * kMs)) == LineStatus::Ok);
  CHECK(line == "HELLO ACK X 1.1");
  CHECK_EQUAL(11U, channel.bytes_sent());
  ::close(peer);
}

TEST(TcpLineChannel, SilenceIsATimeoutByTheDeadlineNotAHang) {
  Listener listener;
  TcpLineChannel channel(clock);
  CHECK(channel.connect("127.0.0.1", listener.port, in(500 * kMs)) == LineStatus::Ok);
  const int peer = listener.accept_one();
  const MonotonicNs before = clock.now_ns();
  std::string_view line;
  CHECK(channel.read_line(line, in(50 * kMs)) == LineStatus::Timeout);
  const MonotonicNs waited = clock.now_ns() - before;
  CHECK(waited >= 50 * kMs);
  CHECK(waited < 500 * kMs);
  ::close(peer);
}

TEST(TcpLineChannel, APeerThatHangsUpIsClosed) {
  Listener listener;
  TcpLineChannel channel(clock);
  CHECK(channel.connect("127.0.0.1", listener.port, in(500 * kMs)) == LineStatus::Ok);
  ::close(listener.accept_one());
  std::string_view line;
  CHECK(channel.read_line(line, in(500 * kMs)) == LineStatus::Closed);
}

TEST(TcpLineChannel, ALineLongerThanTheBufferIsRefusedNotTruncated) {
  Listener listener;
  TcpLineChannel channel(clock);
  CHECK(channel.connect("127.0.0.1", listener.port, in(500 * kMs)) == LineStatus::Ok);
  const int peer = listener.accept_one();
  write_all(peer, std::string(TcpLineChannel::kMaxLine + 10, 'x') + "\n");
  std::string_view line;
  CHECK(channel.read_line(line, in(500 * kMs)) == LineStatus::TooLong);
  CHECK(channel.send_line(std::string(TcpLineChannel::kMaxLine + 1, 'y'), in(500 * kMs)) == LineStatus::TooLong);
  ::close(peer);
}

TEST(TcpLineChannel, NothingListeningIsRefusedAtOnceAndANameIsNotLookedUp) {
  int port = 0;
  {
    Listener gone;
    port = gone.port;
  }
  TcpLineChannel channel(clock);
  CHECK(channel.connect("127.0.0.1", static_cast<std::uint16_t>(port), in(500 * kMs)) == LineStatus::Failed);
  CHECK_EQUAL(ECONNREFUSED, channel.last_errno());
  CHECK_FALSE(channel.is_open());
  CHECK(channel.connect("localhost", static_cast<std::uint16_t>(port), in(500 * kMs)) == LineStatus::Failed);
  CHECK_EQUAL(EINVAL, channel.last_errno());
  std::string_view line;
  CHECK(channel.read_line(line, in(10 * kMs)) == LineStatus::Closed);
}
