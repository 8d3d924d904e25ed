// A CanChannel over a socket descriptor, and the opening of a CAN_RAW socket on an interface.
#include "hal/socketcan/fd_can_channel.hpp"

#include <fcntl.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "hal/socketcan/can_error_frames.hpp"

namespace stencil::hal::socketcan {

namespace {
constexpr int kMinimumReceiveBufferBytes = 128 * 1024;
}  // namespace

FdCanChannel::~FdCanChannel() {
  if (fd_ >= 0) ::close(fd_);
}

TransferStatus FdCanChannel::receive(can_frame& frame) {
  // Room for a CAN FD frame, so one that is too long shows as the wrong size, not as a cut frame.
  alignas(can_frame) unsigned char buffer[sizeof(canfd_frame)];
  const ssize_t received = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);
  if (received < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return TransferStatus::WouldBlock;
    return errno == ECONNRESET || errno == ENOTCONN ? TransferStatus::Closed : TransferStatus::Error;
  }
  if (received == 0) return TransferStatus::Closed;  // a stream or seqpacket peer closed its end
  if (static_cast<std::size_t>(received) != sizeof(can_frame)) return TransferStatus::WrongSize;
  std::memcpy(&frame, buffer, sizeof(can_frame));
  return TransferStatus::Done;
}

TransferStatus FdCanChannel::send(const can_frame& frame) {
  const ssize_t sent = ::send(fd_, &frame, sizeof frame, MSG_DONTWAIT | MSG_NOSIGNAL);
  if (sent == static_cast<ssize_t>(sizeof frame)) return TransferStatus::Done;
  if (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS || errno == EINTR)) {
    return TransferStatus::WouldBlock;
  }
  if (sent < 0 && (errno == EPIPE || errno == ECONNRESET || errno == ENOTCONN)) return TransferStatus::Closed;
  return TransferStatus::Error;
}

int open_can_raw_socket(const std::string& interface, const canid_t* receive_ids, std::size_t id_count,
                        std::string& error) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    error = "CAN interface '" + interface + "': expected a name of 1 to " + std::to_string(IFNAMSIZ - 1) + " characters";
    return -1;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    error = "CAN interface " + interface + ": socket(PF_CAN, SOCK_RAW, CAN_RAW): " + std::strerror(errno);
    return -1;
  }
  // The backend's first read tells a backlog that overflowed the buffer from a short one by its size
  // (socketcan_haptic_device.hpp): that needs a buffer that holds several reads' worth of frames. The
  // default (rmem_default, 212992 bytes, about 277 frames) does; a host tuned below 128 KiB is raised
  // to it (the kernel doubles what is asked: 64 KiB asked, 128 KiB given, over 128 frames at up to
  // 1 KiB each), as far as net.core.rmem_max allows.
  int receive_buffer_bytes = 0;
  socklen_t option_length = sizeof receive_buffer_bytes;
  if (::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, &option_length) == 0 &&
      receive_buffer_bytes < kMinimumReceiveBufferBytes) {
    const int requested = kMinimumReceiveBufferBytes / 2;
    static_cast<void>(::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &requested, sizeof requested));
  }
  ifreq request{};
  std::memcpy(request.ifr_name, interface.c_str(), interface.size() + 1);
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    error = "CAN interface " + interface + ": no such interface (SIOCGIFINDEX: " + std::strerror(errno) + ")";
    ::close(fd);
    return -1;
  }
  std::vector<can_filter> filters;
  for (std::size_t index = 0; index < id_count; ++index) {
    filters.push_back(can_filter{receive_ids[index], CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
  }
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                   static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0) {
    error = "CAN interface " + interface + ": setsockopt(CAN_RAW_FILTER): " + std::strerror(errno);
    ::close(fd);
    return -1;
  }
  // Without this a bus-off, a controller that drops frames or a device gone from the bus would show
  // only as poses that stop coming; with it the driver's error frames arrive among the data frames
  // (CAN_ERR_FLAG set) and the backend stops the link naming what happened.
  const can_err_mask_t error_classes = kSubscribedErrorClasses;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_classes, sizeof error_classes) != 0) {
    error = "CAN interface " + interface + ": setsockopt(CAN_RAW_ERR_FILTER): " + std::strerror(errno);
    ::close(fd);
    return -1;
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    error = "CAN interface " + interface + ": bind: " + std::strerror(errno);
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace stencil::hal::socketcan
