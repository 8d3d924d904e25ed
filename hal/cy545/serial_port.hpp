// The RS-232 port to the CY545: opened exclusively and configured once (8N1 at the rig's baud rate,
// raw, no hardware flow control), then byte I/O that never waits past a deadline.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/clock.hpp"

namespace stencil::hal::cy545 {

enum class PortIo : std::uint8_t {
  Ok,
  TimedOut,  // the deadline passed first
  Closed,    // the other end hung up (unplugged cable, closed pseudo-terminal)
  Failed,    // another error from the port
};

class SerialPort {
 public:
  SerialPort() = default;
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Init-time. Opens `path` and holds it for this program alone: an advisory flock (refuses a
  // second rig, even as root) and TIOCEXCL (any other non-root open fails with EBUSY). A port
  // another program holds locked or exclusively is refused, "in use by another program". Then
  // configures it, 8N1 at `baud` (the rig's: 9600, 19200, 38400, 57600 or 115200), HUPCL cleared
  // so that closing the port leaves DTR and RTS up. False with a message naming the path and the
  // failing step (cannot open, not a tty, in use, termios refused) in `error`.
  [[nodiscard]] bool open(const char* path, std::uint32_t baud, char (&error)[256]);
  // Init-time. Clears the exclusive flag and closes the port, which releases the lock.
  void close();
  [[nodiscard]] bool is_open() const { return fd_ >= 0; }
  // A real UART has modem lines (CTS holds the bytes while the chip is busy); a pseudo-terminal
  // has none, so the driver paces commands by their duration instead.
  [[nodiscard]] bool has_modem_lines() const { return modem_lines_; }

  // Writes every byte by the deadline.
  [[nodiscard]] PortIo write_all(std::string_view bytes, MonotonicNs deadline_ns, const Clock& clock);
  // Reads bytes up to and including a carriage return into `buffer` (at most `capacity` bytes;
  // more before a CR is Failed). `size` is what was read, whatever the outcome.
  [[nodiscard]] PortIo read_line(char* buffer, std::size_t capacity, std::size_t& size, MonotonicNs deadline_ns,
                                 const Clock& clock);
  // Drops whatever waits to be read (stale replies before a fresh exchange).
  void discard_input();

 private:
  int fd_ = -1;
  bool modem_lines_ = false;
};

}  // namespace stencil::hal::cy545
