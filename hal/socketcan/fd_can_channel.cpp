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

namespace stencil::hal::socketcan {

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
