// CanChannel: where whole can_frames go out and come in without ever waiting (a CAN_RAW socket on the
// rig, one end of a SOCK_SEQPACKET socket pair in tests).
#pragma once

#include <linux/can.h>

#include <cstdint>

namespace stencil::hal::socketcan {

enum class TransferStatus : std::uint8_t {
  Done,        // one frame moved
  WouldBlock,  // receive: nothing waiting; send: the queue is full (the frame was not sent)
  WrongSize,   // receive: a message that is not exactly one can_frame (consumed, not delivered)
  Closed,      // the other end is gone
  Error,       // any other failure of the underlying call
};

class CanChannel {
 public:
  CanChannel() = default;
  CanChannel(const CanChannel&) = delete;
  CanChannel& operator=(const CanChannel&) = delete;

  // One frame if one is waiting. Never blocks. Real-time safe in the sense of the cycle: one
  // non-blocking system call, no allocation (the fd implementation is kept out of the checked core
  // because it makes a system call).
  [[nodiscard]] virtual TransferStatus receive(can_frame& frame) = 0;

  // Queues one frame. Never blocks.
  [[nodiscard]] virtual TransferStatus send(const can_frame& frame) = 0;

 protected:
  ~CanChannel() = default;  // not deleted through the interface (see hal/haptic_device.hpp)
};

}  // namespace stencil::hal::socketcan
