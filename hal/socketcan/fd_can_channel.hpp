// FdCanChannel: a CanChannel over a socket file descriptor (a CAN_RAW socket bound to can0/vcan0, or
// one end of a SOCK_SEQPACKET socket pair), and the init-time opening of a CAN_RAW socket.
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <string>

#include "hal/socketcan/can_channel.hpp"

namespace stencil::hal::socketcan {

class FdCanChannel final : public CanChannel {
 public:
  // Takes ownership of `fd` (closed by the destructor). Init-time.
  explicit FdCanChannel(int fd) : fd_(fd) {}
  FdCanChannel(const FdCanChannel&) = delete;
  FdCanChannel& operator=(const FdCanChannel&) = delete;
  ~FdCanChannel();

  // recv / send with MSG_DONTWAIT: never block whatever the descriptor's flags. No allocation.
  [[nodiscard]] TransferStatus receive(can_frame& frame) override;
  [[nodiscard]] TransferStatus send(const can_frame& frame) override;

  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_;
};

// Opens a CAN_RAW socket on `interface` (e.g. "can0", "vcan0"), non-blocking, receiving only the
// standard IDs in `receive_ids` and the error frames of kSubscribedErrorClasses (can_error_frames.hpp).
// Init-time. It does not check the bitrate (can_interface_bitrate.hpp does). Returns the descriptor,
// or -1 with `error` naming the interface and the call that failed.
[[nodiscard]] int open_can_raw_socket(const std::string& interface, const canid_t* receive_ids, std::size_t id_count,
                                      std::string& error);

}  // namespace stencil::hal::socketcan
