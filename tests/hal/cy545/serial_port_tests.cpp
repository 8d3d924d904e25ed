// The CY545's serial port on a real pseudo-terminal: held exclusively (TIOCEXCL and flock) so that a
// second rig, a getty or a modem manager cannot write to the chip mid-job, released on close, and
// HUPCL cleared so that closing the port does not drop the modem lines.
#include <fcntl.h>
#include <grp.h>
#include <stdlib.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/cy545/serial_port.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using stencil::hal::cy545::SerialPort;

namespace {

// A pseudo-terminal pair; the slave is the port under test, the master stays open for the whole
// test so that the slave's tty lives on between the port's opens.
struct Pty {
  int master_fd = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  std::string slave_path = make_slave(master_fd);

  static std::string make_slave(int master_fd) {
    CHECK_TEXT(master_fd >= 0, std::strerror(errno));
    CHECK(grantpt(master_fd) == 0);
    CHECK(unlockpt(master_fd) == 0);
    std::array<char, 128> name{};
    CHECK(ptsname_r(master_fd, name.data(), name.size()) == 0);
    return name.data();
  }
  ~Pty() { ::close(master_fd); }
  const char* path() const { return slave_path.c_str(); }
};

// The rig's line (57600 8N1): the port is opened at it.
constexpr std::uint32_t kBaud = stencil::board::sherline_suzuki::kRig.serial_baud;

// Exit codes of the unprivileged child below that are not an errno.
constexpr int kOpened = 0;
constexpr int kCannotDropPrivileges = 250;

// What an ordinary program (a getty, a modem manager) gets from a plain open(2) of `path`: 0 when it
// opened, else its errno; -1 when this test runs as root and cannot become an ordinary user to find
// out (root with CAP_SYS_ADMIN is let through TIOCEXCL, so root's own open proves nothing).
int plain_open_errno(const char* path) {
  if (geteuid() != 0) {
    const int fd = ::open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd >= 0) {
      ::close(fd);
      return 0;
    }
    return errno;
  }
  // As root: let "nobody" at the test's own pty, and ask a child running as nobody to open it.
  if (chmod(path, 0666) != 0) {
    return -1;
  }
  const pid_t child = fork();
  if (child < 0) {
    return -1;
  }
  if (child == 0) {
    constexpr gid_t kNobodyGroup = 65534;
    constexpr uid_t kNobody = 65534;
    if (setgroups(0, nullptr) != 0 || setgid(kNobodyGroup) != 0 || setuid(kNobody) != 0) {
      _exit(kCannotDropPrivileges);
    }
    const int fd = ::open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    _exit(fd >= 0 ? kOpened : errno);
  }
  int status = 0;
  if (waitpid(child, &status, 0) != child || !WIFEXITED(status) || WEXITSTATUS(status) == kCannotDropPrivileges) {
    return -1;
  }
  return WEXITSTATUS(status);
}

bool held_by_another_program(const char* error) { return std::strstr(error, "in use by another program") != nullptr; }

}  // namespace

TEST_GROUP(SerialPort){};

TEST(SerialPort, ASecondOpenOfAHeldPortIsRefusedNamingThePath) {
  Pty pty;
  SerialPort first;
  char error[256] = {};
  CHECK_TEXT(first.open(pty.path(), kBaud, error), error);

  SerialPort second;
  CHECK_FALSE_TEXT(second.open(pty.path(), kBaud, error), "a second rig opened a port the first one holds");
  CHECK_FALSE(second.is_open());
  STRCMP_CONTAINS(pty.path(), error);
  CHECK_TEXT(held_by_another_program(error), error);
  CHECK(first.is_open());
}

TEST(SerialPort, APortLockedByAnotherProgramIsRefusedEvenAsRoot) {
  // flock is what stops a second rig started as root, which TIOCEXCL lets through.
  Pty pty;
  const int other = ::open(pty.path(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  CHECK(other >= 0);
  CHECK(flock(other, LOCK_EX | LOCK_NB) == 0);

  SerialPort port;
  char error[256] = {};
  CHECK_FALSE_TEXT(port.open(pty.path(), kBaud, error), "opened a port another program holds locked");
  STRCMP_CONTAINS(pty.path(), error);
  CHECK_TEXT(held_by_another_program(error), error);
  STRCMP_CONTAINS("locked", error);

  ::close(other);
  CHECK_TEXT(port.open(pty.path(), kBaud, error), error);
}

TEST(SerialPort, APortAnotherProgramHoldsExclusivelyIsRefusedEvenAsRoot) {
  // A terminal program or getty that set TIOCEXCL: an ordinary user's open fails with EBUSY, root's
  // goes through and must be refused all the same, without clearing the other program's flag.
  Pty pty;
  const int other = ::open(pty.path(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  CHECK(other >= 0);
  CHECK(ioctl(other, TIOCEXCL) == 0);

  SerialPort port;
  char error[256] = {};
  CHECK_FALSE_TEXT(port.open(pty.path(), kBaud, error), "opened a port another program holds exclusively");
  STRCMP_CONTAINS(pty.path(), error);
  CHECK_TEXT(held_by_another_program(error), error);
  STRCMP_CONTAINS("exclusive", error);
  int exclusive = 0;
  CHECK(ioctl(other, TIOCGEXCL, &exclusive) == 0);
  CHECK_TEXT(exclusive != 0, "the refused open cleared the other program's exclusive flag");

  CHECK(ioctl(other, TIOCNXCL) == 0);
  ::close(other);
  CHECK_TEXT(port.open(pty.path(), kBaud, error), error);
}

TEST(SerialPort, APortOpensAgainOnceItsHolderClosesIt) {
  Pty pty;
  SerialPort first;
  SerialPort second;
  char error[256] = {};
  CHECK_TEXT(first.open(pty.path(), kBaud, error), error);
  CHECK_FALSE_TEXT(second.open(pty.path(), kBaud, error), "a second rig opened a port the first one holds");

  first.close();
  CHECK_FALSE(first.is_open());
  CHECK_TEXT(second.open(pty.path(), kBaud, error), error);
  second.close();

  // The exclusive flag lives on the tty, not the descriptor: a pseudo-terminal (or a port some
  // other program keeps open) would stay exclusive after close unless close clears it.
  const int after = ::open(pty.path(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (after >= 0) {  // as an ordinary user a flag left behind makes this open fail (checked below)
    int exclusive = 0;
    CHECK(ioctl(after, TIOCGEXCL, &exclusive) == 0);
    ::close(after);
    CHECK_TEXT(exclusive == 0, "the closed port was left exclusive");
  }
  const int plain = plain_open_errno(pty.path());
  if (plain < 0) {
    UT_PRINT("skipped: running as root and cannot become an ordinary user to open the closed port");
    return;
  }
  LONGS_EQUAL_TEXT(0, plain, std::strerror(plain));
}

TEST(SerialPort, AnotherProgramsPlainOpenIsRefusedWithEbusyWhileThePortIsHeld) {
  Pty pty;
  SerialPort port;
  char error[256] = {};
  CHECK_TEXT(port.open(pty.path(), kBaud, error), error);

  const int plain = plain_open_errno(pty.path());
  if (plain < 0) {
    UT_PRINT("skipped: root bypasses TIOCEXCL and this test cannot become an ordinary user to check it");
    return;
  }
  LONGS_EQUAL_TEXT(EBUSY, plain, plain == 0 ? "an ordinary program opened the held port" : std::strerror(plain));
}

TEST(SerialPort, ARefusedOpenLeavesTheHolderExclusive) {
  // The refused rig must not touch the port: clearing TIOCEXCL on its way out would open the
  // holder's port to a getty.
  Pty pty;
  SerialPort first;
  SerialPort second;
  char error[256] = {};
  CHECK_TEXT(first.open(pty.path(), kBaud, error), error);
  CHECK_FALSE(second.open(pty.path(), kBaud, error));
  second.close();

  const int plain = plain_open_errno(pty.path());
  if (plain < 0) {
    UT_PRINT("skipped: root bypasses TIOCEXCL and this test cannot become an ordinary user to check it");
    return;
  }
  LONGS_EQUAL_TEXT(EBUSY, plain, plain == 0 ? "an ordinary program opened the held port" : std::strerror(plain));
}

TEST(SerialPort, HangUpOnCloseIsClearSoTheModemLinesStayUp) {
  // A real UART starts with HUPCL set (the kernel's standard settings); a pseudo-terminal's slave
  // starts without it, so set it as the UART would have it. The master's termios calls read and set
  // the slave's settings, which are the port's.
  Pty pty;
  termios settings{};
  CHECK(tcgetattr(pty.master_fd, &settings) == 0);
  settings.c_cflag |= HUPCL;
  CHECK(tcsetattr(pty.master_fd, TCSANOW, &settings) == 0);
  CHECK(tcgetattr(pty.master_fd, &settings) == 0);
  CHECK_TEXT((settings.c_cflag & HUPCL) != 0, "the pseudo-terminal did not keep HUPCL: the test proves nothing");

  SerialPort port;
  char error[256] = {};
  CHECK_TEXT(port.open(pty.path(), kBaud, error), error);

  CHECK(tcgetattr(pty.master_fd, &settings) == 0);
  CHECK_EQUAL(0u, settings.c_cflag & HUPCL);
  // And the rest of the set-up is still there.
  CHECK_EQUAL(static_cast<tcflag_t>(CS8), settings.c_cflag & CSIZE);
  CHECK_EQUAL(static_cast<speed_t>(B57600), cfgetospeed(&settings));
}

// Issue 18, item 7: the CY545 drives CTS only once a Mode command enables it (manual, chapter 16),
// which the driver does not send; with CRTSCTS on a port with modem lines the kernel would hold
// every byte or none on a level that means nothing. The port comes out with it off, whatever the
// last program left (here set beforehand, as a UART's earlier user might have).
TEST(SerialPort, HardwareFlowControlIsOffWhateverTheLastProgramLeft) {
  Pty pty;
  termios settings{};
  CHECK(tcgetattr(pty.master_fd, &settings) == 0);
  settings.c_cflag |= CRTSCTS;
  CHECK(tcsetattr(pty.master_fd, TCSANOW, &settings) == 0);
  CHECK(tcgetattr(pty.master_fd, &settings) == 0);
  CHECK_TEXT((settings.c_cflag & CRTSCTS) != 0, "the pseudo-terminal did not keep CRTSCTS: the test proves nothing");

  SerialPort port;
  char error[256] = {};
  CHECK_TEXT(port.open(pty.path(), kBaud, error), error);

  CHECK(tcgetattr(pty.master_fd, &settings) == 0);
  CHECK_EQUAL(0u, settings.c_cflag & CRTSCTS);
}

// The baud rate is the board's (the rig's facts): one the port does not offer is refused by name,
// before the port is touched.
TEST(SerialPort, ABaudRateThePortDoesNotOfferIsRefused) {
  Pty pty;
  SerialPort port;
  char error[256] = {};
  CHECK_FALSE(port.open(pty.path(), 12345, error));
  CHECK_FALSE(port.is_open());
  STRCMP_CONTAINS("12345 baud: expected 9600, 19200, 38400, 57600 or 115200", error);
  CHECK_TEXT(port.open(pty.path(), kBaud, error), error);
}
