// A tiny serial client for the fake CY545's tests: opens the pty slave raw and writes and reads raw bytes.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <stdexcept>
#include <string>
#include <string_view>

namespace stencil::sim::cy545::test {

class PtyTestClient {
 public:
  explicit PtyTestClient(const std::string& path) {
    fd_ = open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error("pty test client: cannot open " + path);
    termios settings{};
    tcgetattr(fd_, &settings);
    cfmakeraw(&settings);
    tcsetattr(fd_, TCSANOW, &settings);
  }
  ~PtyTestClient() { close(fd_); }
  PtyTestClient(const PtyTestClient&) = delete;
  PtyTestClient& operator=(const PtyTestClient&) = delete;

  // Writes every byte; false when the pty refuses (e.g. EIO after the fake closed it).
  bool write_raw(std::string_view bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t count = write(fd_, bytes.data() + sent, bytes.size() - sent);
      if (count > 0) {
        sent += static_cast<std::size_t>(count);
      } else if (count < 0 && errno == EAGAIN) {
        pollfd request{fd_, POLLOUT, 0};
        poll(&request, 1, 100);
      } else if (!(count < 0 && errno == EINTR)) {
        last_errno_ = errno;
        return false;
      }
    }
    return true;
  }

  // Reads until a CR arrives or `timeout_ms` passes; returns what came (CR included).
  std::string read_until_cr(int timeout_ms) {
    std::string received;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (received.find('\r') == std::string::npos) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd request{fd_, POLLIN, 0};
      if (poll(&request, 1, static_cast<int>(left.count())) <= 0) break;
      char byte = 0;
      const ssize_t count = read(fd_, &byte, 1);
      if (count == 1) {
        received.push_back(byte);
      } else if (count == 0 || (count < 0 && errno != EAGAIN && errno != EINTR)) {
        last_errno_ = count == 0 ? 0 : errno;
        hung_up_ = true;
        break;
      }
    }
    return received;
  }

  // Whatever arrives within `wait_ms` (for checking that nothing does).
  std::string read_for(int wait_ms) {
    std::string received;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_ms);
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd request{fd_, POLLIN, 0};
      if (poll(&request, 1, static_cast<int>(left.count())) <= 0) break;
      char bytes[64];
      const ssize_t count = read(fd_, bytes, sizeof bytes);
      if (count > 0) {
        received.append(bytes, static_cast<std::size_t>(count));
      } else if (count == 0 || (count < 0 && errno != EAGAIN && errno != EINTR)) {
        last_errno_ = count == 0 ? 0 : errno;
        hung_up_ = true;
        break;
      }
    }
    return received;
  }

  [[nodiscard]] bool hung_up() const { return hung_up_; }
  [[nodiscard]] int last_errno() const { return last_errno_; }

 private:
  int fd_ = -1;
  bool hung_up_ = false;
  int last_errno_ = 0;
};

}  // namespace stencil::sim::cy545::test
