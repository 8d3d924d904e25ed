// FdCanChannel and open_can_raw_socket (hal/socketcan/fd_can_channel.cpp): whole frames in and out of
// a SOCK_SEQPACKET socket pair without ever waiting, each failure mapped to its TransferStatus (nothing
// waiting, a queue full, a message of the wrong size, a peer gone), the descriptor closed with the
// channel; and the init-time opening of a CAN_RAW socket refusing bad interface names with the reason.
#include <fcntl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <string>

#include "hal/socketcan/can_frame_layout.hpp"
#include "hal/socketcan/fd_can_channel.hpp"
#include "tests/hal/socketcan/can_strings.hpp"
#include "tests/support/can_socket_pair.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
namespace can = hal::socketcan;
using can::TransferStatus;

namespace {

can_frame frame_with(canid_t id, std::uint8_t first_byte) {
  can_frame frame{};
  frame.can_id = id;
  frame.len = can::kFrameBytes;
  frame.data[0] = first_byte;
  frame.data[7] = 0xA5U;
  return frame;
}

}  // namespace

TEST_GROUP(FdCanChannel) {
  test::CanSocketPair sockets;
};

TEST(FdCanChannel, AFrameSentArrivesWholeAtTheOtherEndInOrder) {
  CHECK_TRUE(sockets.open());
  CHECK_EQUAL(TransferStatus::Done, sockets.host.send(frame_with(can::kForceId, 1)));
  CHECK_EQUAL(TransferStatus::Done, sockets.host.send(frame_with(can::kTorqueId, 2)));
  can_frame received{};
  CHECK_EQUAL(TransferStatus::Done, sockets.device.receive(received));
  CHECK_EQUAL(can::kForceId, received.can_id);
  CHECK_EQUAL(1U, received.data[0]);
  CHECK_EQUAL(0xA5U, received.data[7]);
  CHECK_EQUAL(TransferStatus::Done, sockets.device.receive(received));
  CHECK_EQUAL(can::kTorqueId, received.can_id);
  CHECK_EQUAL(2U, received.data[0]);
}

TEST(FdCanChannel, NothingWaitingIsWouldBlockAtOnceAndTheFrameIsUntouched) {
  can_frame received = frame_with(0x7FF, 42);
  CHECK_EQUAL(TransferStatus::WouldBlock, sockets.device.receive(received));
  CHECK_EQUAL(0x7FFU, received.can_id);
  CHECK_EQUAL(42U, received.data[0]);
}

TEST(FdCanChannel, NeverBlocksEvenOnABlockingDescriptor) {
  CHECK_EQUAL(0, ::fcntl(sockets.device.fd(), F_GETFL) & O_NONBLOCK);  // the socket pair blocks
  can_frame received{};
  CHECK_EQUAL(TransferStatus::WouldBlock, sockets.device.receive(received));  // returns: MSG_DONTWAIT
}

TEST(FdCanChannel, AMessageThatIsNotOneFrameIsConsumedAsTheWrongSize) {
  const char shorter[10] = {};
  CHECK_EQUAL(10, ::send(sockets.host.fd(), shorter, sizeof shorter, 0));
  unsigned char longer[sizeof(canfd_frame)] = {};  // a CAN FD frame: too long, yet not cut to fit
  CHECK_EQUAL(static_cast<ssize_t>(sizeof longer), ::send(sockets.host.fd(), longer, sizeof longer, 0));
  CHECK_EQUAL(TransferStatus::Done, sockets.host.send(frame_with(can::kForceId, 3)));

  can_frame received = frame_with(0x7FF, 42);
  CHECK_EQUAL(TransferStatus::WrongSize, sockets.device.receive(received));
  CHECK_EQUAL(0x7FFU, received.can_id);  // not delivered
  CHECK_EQUAL(TransferStatus::WrongSize, sockets.device.receive(received));
  CHECK_EQUAL(TransferStatus::Done, sockets.device.receive(received));  // the next frame is whole
  CHECK_EQUAL(3U, received.data[0]);
}

TEST(FdCanChannel, AFullQueueIsWouldBlockAndTheFrameIsNotSent) {
  int sent = 0;
  TransferStatus status = TransferStatus::Done;
  while (sent < 1'000'000 && (status = sockets.host.send(frame_with(can::kForceId, 0))) == TransferStatus::Done) ++sent;
  CHECK_EQUAL(TransferStatus::WouldBlock, status);
  CHECK_TRUE(sent > 0);
  int received_count = 0;
  can_frame received{};
  while (sockets.device.receive(received) == TransferStatus::Done) ++received_count;
  CHECK_EQUAL(sent, received_count);  // every frame that was Done arrived; the refused one did not
}

TEST(FdCanChannel, APeerThatClosedIsClosedOnBothCalls) {
  int fds[2];
  CHECK_EQUAL(0, ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds));
  can::FdCanChannel device(fds[1]);
  const can_frame sent = frame_with(can::kForceId, 1);
  CHECK_EQUAL(static_cast<ssize_t>(sizeof sent), ::send(fds[0], &sent, sizeof sent, 0));
  ::close(fds[0]);  // the peer is gone
  can_frame received{};
  CHECK_EQUAL(TransferStatus::Done, device.receive(received));  // what was sent before still arrives
  CHECK_EQUAL(TransferStatus::Closed, device.receive(received));
  CHECK_EQUAL(TransferStatus::Closed, device.send(frame_with(can::kPoseAId, 1)));  // and no SIGPIPE
}

TEST(FdCanChannel, AnInvalidDescriptorIsAnErrorNotAHang) {
  can::FdCanChannel broken(-1);
  can_frame frame{};
  CHECK_EQUAL(TransferStatus::Error, broken.receive(frame));
  CHECK_EQUAL(TransferStatus::Error, broken.send(frame));
}

TEST(FdCanChannel, TheChannelClosesTheDescriptorItOwns) {
  int fds[2];
  CHECK_EQUAL(0, ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds));
  { can::FdCanChannel channel(fds[0]); }
  CHECK_EQUAL(-1, ::fcntl(fds[0], F_GETFD));
  CHECK_EQUAL(EBADF, errno);
  ::close(fds[1]);
}

TEST_GROUP(OpenCanRawSocket){};

TEST(OpenCanRawSocket, AnEmptyOrOverlongInterfaceNameIsRefusedSayingWhatFits) {
  std::string error;
  const canid_t ids[] = {can::kPoseAId};
  CHECK_EQUAL(-1, can::open_can_raw_socket("", ids, 1, error));
  STRCMP_EQUAL("CAN interface '': expected a name of 1 to 15 characters", error.c_str());
  CHECK_EQUAL(-1, can::open_can_raw_socket("a-name-of-sixteen", ids, 1, error));
  STRCMP_CONTAINS("'a-name-of-sixteen'", error.c_str());
}

TEST(OpenCanRawSocket, AnInterfaceThatDoesNotExistIsNamedWithTheCallThatFailed) {
  std::string error;
  const canid_t ids[] = {can::kPoseAId};
  CHECK_EQUAL(-1, can::open_can_raw_socket("nosuchcan9", ids, 1, error));
  // Where the kernel has no CAN sockets the socket() call fails first; otherwise the name lookup.
  STRCMP_CONTAINS("CAN interface nosuchcan9: ", error.c_str());
  CHECK_TRUE(error.find("no such interface") != std::string::npos || error.find("socket(PF_CAN") != std::string::npos);
}
