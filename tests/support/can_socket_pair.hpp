// Two FdCanChannels joined by a SOCK_SEQPACKET socket pair: what a test uses in place of a CAN bus
// (a vcan interface cannot be created here). Every frame sent on one end arrives at once at the other.
#pragma once

#include <sys/socket.h>

#include "hal/socketcan/fd_can_channel.hpp"

namespace stencil::test {

struct CanSocketPair {
  // The two descriptors; -1 when socketpair() failed (the channels then fail every call).
  struct Ends {
    int fds[2] = {-1, -1};
    Ends() { static_cast<void>(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds)); }
  } ends;  // first: the channels below take its two descriptors
  hal::socketcan::FdCanChannel host{ends.fds[0]};
  hal::socketcan::FdCanChannel device{ends.fds[1]};

  [[nodiscard]] bool open() const { return ends.fds[0] >= 0 && ends.fds[1] >= 0; }
};

}  // namespace stencil::test
