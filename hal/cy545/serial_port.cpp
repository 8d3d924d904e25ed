// The CY545's serial port: termios set-up and deadline-bounded byte I/O with poll().
#include "hal/cy545/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace stencil::hal::cy545 {
namespace {

// Milliseconds until the deadline for poll(), rounded up so a wait never ends early; 0 when past.
int poll_timeout_ms(MonotonicNs deadline_ns, const Clock& clock) {
  const MonotonicNs left = deadline_ns - clock.now_ns();
  if (left <= 0) {
    return 0;
  }
  const MonotonicNs ms = (left + 999'999) / 1'000'000;
  return ms > 60'000 ? 60'000 : static_cast<int>(ms);
}

// The termios speed of a baud rate; B0 for a rate not offered here.
speed_t speed_of(std::uint32_t baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    default:
      return B0;
  }
}

}  // namespace

SerialPort::~SerialPort() { close(); }

void SerialPort::close() {
  if (fd_ >= 0) {
    // The exclusive flag belongs to the tty, not to this descriptor: a port that stays open
    // elsewhere (a pseudo-terminal's master, a program that opened it before us) would stay
    // exclusive after we are gone. close() releases the flock.
    ioctl(fd_, TIOCNXCL);
    ::close(fd_);
    fd_ = -1;
  }
}

bool SerialPort::open(const char* path, std::uint32_t baud, char (&error)[256]) {
  close();
  if (speed_of(baud) == B0) {
    std::snprintf(error, sizeof error, "%s: %u baud: expected 9600, 19200, 38400, 57600 or 115200", path,
                  static_cast<unsigned>(baud));
    return false;
  }
  const int fd = ::open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0 && errno == EBUSY) {
    // Another program holds the port with TIOCEXCL.
    std::snprintf(error, sizeof error, "%s: the serial port is in use by another program (exclusive); stop it first",
                  path);
    return false;
  }
  if (fd < 0) {
    std::snprintf(error, sizeof error, "%s: cannot open the serial port: %s", path, std::strerror(errno));
    return false;
  }
  if (!isatty(fd)) {
    std::snprintf(error, sizeof error, "%s: not a serial port (a tty was expected)", path);
    ::close(fd);
    return false;
  }
  // Only one program may talk to the chip: a second rig would send `I` and reset the CY545 mid-job,
  // a getty or a modem manager would write to it. The advisory lock refuses a second rig even as
  // root (and any program that locks ports the same way); it is taken before TIOCEXCL so that a
  // refused open never touches the holder's exclusive flag.
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno == EWOULDBLOCK) {
      std::snprintf(error, sizeof error, "%s: the serial port is in use by another program (locked); stop it first",
                    path);
    } else {
      std::snprintf(error, sizeof error, "%s: cannot lock the serial port: %s", path, std::strerror(errno));
    }
    ::close(fd);
    return false;
  }
  // Root's open(2) goes through another program's TIOCEXCL: refuse that port too, and never clear
  // the other program's flag (our close() would).
  int exclusive = 0;
  if (ioctl(fd, TIOCGEXCL, &exclusive) == 0 && exclusive != 0) {
    std::snprintf(error, sizeof error, "%s: the serial port is in use by another program (exclusive); stop it first",
                  path);
    ::close(fd);
    return false;
  }
  // TIOCEXCL makes every later open(2) of the port fail with EBUSY, except by root (CAP_SYS_ADMIN),
  // whether or not the opener knows about locks.
  if (ioctl(fd, TIOCEXCL) != 0) {
    std::snprintf(error, sizeof error, "%s: cannot take the serial port exclusively: %s", path, std::strerror(errno));
    ::close(fd);
    return false;
  }
  // From here a failure must clear the exclusive flag it set (close() does both).
  fd_ = fd;
  termios settings{};
  if (tcgetattr(fd, &settings) != 0) {
    std::snprintf(error, sizeof error, "%s: cannot read the port settings: %s", path, std::strerror(errno));
    close();
    return false;
  }
  // A pseudo-terminal has no modem lines: TIOCMGET fails on it.
  int lines = 0;
  modem_lines_ = ioctl(fd, TIOCMGET, &lines) == 0;
  cfmakeraw(&settings);
  cfsetispeed(&settings, speed_of(baud));
  cfsetospeed(&settings, speed_of(baud));
  settings.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB);
  settings.c_cflag |= CS8 | CREAD | CLOCAL;
  // No hang-up on close: with HUPCL the kernel drops DTR and RTS when the port closes, and the
  // MMC-4S/CY545 must not see its modem lines drop when this program exits or restarts.
  settings.c_cflag &= ~static_cast<tcflag_t>(HUPCL);
  // No hardware flow control, modem lines or not: the CY545 drives CTS (its user bit 6) only once a
  // Mode command enables it (manual, chapter 16), which the driver does not send, so the line's level
  // says nothing and CRTSCTS could hold every byte or none. Without CTS the host must give the chip
  // the time to take each command (chapter 16): the driver paces itself (Cy545Config).
  settings.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS);
  settings.c_cc[VMIN] = 1;  // with O_NONBLOCK: EAGAIN when nothing waits (VMIN 0 would read 0, like a hang-up)
  settings.c_cc[VTIME] = 0;
  if (tcsetattr(fd, TCSANOW, &settings) != 0) {
    std::snprintf(error, sizeof error, "%s: cannot set %u 8N1 raw: %s", path, static_cast<unsigned>(baud), std::strerror(errno));
    close();
    return false;
  }
  return true;
}

PortIo SerialPort::write_all(std::string_view bytes, MonotonicNs deadline_ns, const Clock& clock) {
  if (fd_ < 0) {
    return PortIo::Failed;
  }
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t count = ::write(fd_, bytes.data() + sent, bytes.size() - sent);
    if (count > 0) {
      sent += static_cast<std::size_t>(count);
      continue;
    }
    if (count < 0 && errno == EIO) {
      return PortIo::Closed;
    }
    if (count < 0 && errno != EAGAIN && errno != EINTR) {
      return PortIo::Failed;
    }
    pollfd request{fd_, POLLOUT, 0};
    const int ready = ::poll(&request, 1, poll_timeout_ms(deadline_ns, clock));
    if (ready == 0) {
      return PortIo::TimedOut;
    }
    if (ready > 0 && (request.revents & POLLHUP) != 0) {
      return PortIo::Closed;
    }
  }
  return PortIo::Ok;
}

PortIo SerialPort::read_line(char* buffer, std::size_t capacity, std::size_t& size, MonotonicNs deadline_ns,
                             const Clock& clock) {
  size = 0;
  if (fd_ < 0) {
    return PortIo::Failed;
  }
  while (true) {
    char byte = 0;
    const ssize_t count = ::read(fd_, &byte, 1);
    if (count == 1) {
      if (size == capacity) {
        return PortIo::Failed;
      }
      buffer[size++] = byte;
      if (byte == '\r') {
        return PortIo::Ok;
      }
      continue;
    }
    if (count == 0 || (count < 0 && errno == EIO)) {
      return PortIo::Closed;  // a pseudo-terminal whose master closed reads EIO
    }
    if (errno != EAGAIN && errno != EINTR) {
      return PortIo::Failed;
    }
    const int timeout = poll_timeout_ms(deadline_ns, clock);
    if (timeout == 0 && clock.now_ns() >= deadline_ns) {
      return PortIo::TimedOut;
    }
    pollfd request{fd_, POLLIN, 0};
    const int ready = ::poll(&request, 1, timeout);
    if (ready == 0) {
      return PortIo::TimedOut;
    }
    if (ready > 0 && (request.revents & (POLLIN)) == 0 && (request.revents & POLLHUP) != 0) {
      return PortIo::Closed;
    }
  }
}

void SerialPort::discard_input() {
  if (fd_ >= 0) {
    tcflush(fd_, TCIFLUSH);
  }
}

}  // namespace stencil::hal::cy545
