// The fake CY545 on a pseudo-terminal: pty set-up, non-blocking byte exchange, fault hooks.
#include "sim/cy545/fake_cy545.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <string>
#include <system_error>

namespace stencil::sim::cy545 {

namespace {

[[noreturn]] void fail(const char* call) {
  throw std::system_error(errno, std::generic_category(), std::string("sim/cy545: fake CY545 pty: ") + call);
}

void make_raw(int fd, const char* what) {
  termios settings{};
  if (tcgetattr(fd, &settings) != 0) fail(what);
  cfmakeraw(&settings);
  if (tcsetattr(fd, TCSANOW, &settings) != 0) fail(what);
}

}  // namespace

FakeCy545::FakeCy545(SimulatedMill& mill, const hal::cy545::Mmc4sWiring& wiring, hal::MonotonicNs start_ns)
    : board_(mill, wiring), chip_(board_, start_ns) {
  master_fd_ = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (master_fd_ < 0) fail("posix_openpt");
  try {
    if (grantpt(master_fd_) != 0) fail("grantpt");
    if (unlockpt(master_fd_) != 0) fail("unlockpt");
    std::array<char, 128> name{};
    if (ptsname_r(master_fd_, name.data(), name.size()) != 0) fail("ptsname_r");
    slave_path_ = name.data();
    own_slave_fd_ = open(slave_path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (own_slave_fd_ < 0) fail("open slave");
    // The line discipline sits on the slave side: raw there means no echo of the driver's bytes, no
    // CR/NL translation either way, every byte passed at once.
    make_raw(own_slave_fd_, "tcsetattr (raw mode)");
  } catch (...) {
    close_pty();
    throw;
  }
}

FakeCy545::~FakeCy545() { close_pty(); }

void FakeCy545::close_pty() {
  if (own_slave_fd_ >= 0) close(own_slave_fd_);
  if (master_fd_ >= 0) close(master_fd_);
  own_slave_fd_ = -1;
  master_fd_ = -1;
}

bool FakeCy545::wait_for_input(int timeout_ms) const {
  if (master_fd_ < 0) return false;
  pollfd request{master_fd_, POLLIN, 0};
  return poll(&request, 1, timeout_ms) > 0 && (request.revents & POLLIN) != 0;
}

void FakeCy545::step(hal::MonotonicNs now_ns) {
  chip_.advance_to(now_ns);
  board_.advance_to(now_ns);
  read_input(now_ns);
  flush_replies();
}

void FakeCy545::read_input(hal::MonotonicNs now_ns) {
  if (master_fd_ < 0) return;
  std::array<std::uint8_t, 256> bytes{};
  hal::MonotonicNs at_ns = now_ns;
  for (;;) {
    const ssize_t count = read(master_fd_, bytes.data(), bytes.size());
    if (count > 0) {
      counters_.bytes_read += count;
      for (ssize_t i = 0; i < count; ++i) {
        chip_.receive(bytes[static_cast<std::size_t>(i)], at_ns);
        at_ns += byte_time_ns_;
      }
      continue;
    }
    if (count < 0 && errno == EINTR) continue;
    return;  // EAGAIN: nothing more now; EIO: no slave open; 0: end of file
  }
}

void FakeCy545::flush_replies() {
  std::string replies = chip_.take_output();
  if (replies.empty()) return;
  if (replies_suppressed_) {
    counters_.replies_suppressed += static_cast<std::int64_t>(replies.size());
    return;
  }
  if (replies_garbled_) {
    for (char& byte : replies) byte = static_cast<char>(static_cast<unsigned char>(byte) ^ 0x80u);
  }
  write_bytes(replies);
}

void FakeCy545::send_unsolicited(std::string_view bytes) { write_bytes(bytes); }

void FakeCy545::write_bytes(std::string_view bytes) {
  if (master_fd_ < 0) {
    counters_.write_failures += static_cast<std::int64_t>(bytes.size());
    return;
  }
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t count = write(master_fd_, bytes.data() + sent, bytes.size() - sent);
    if (count > 0) {
      sent += static_cast<std::size_t>(count);
      continue;
    }
    if (count < 0 && errno == EINTR) continue;
    break;
  }
  counters_.bytes_written += static_cast<std::int64_t>(sent);
  counters_.write_failures += static_cast<std::int64_t>(bytes.size() - sent);
}

}  // namespace stencil::sim::cy545
