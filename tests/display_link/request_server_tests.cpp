// The controller's request server over a real Unix socket: the feed handed over with the Welcome,
// requests decided and queued for the cycle, and everything it refuses counted: the limits, a rate
// too high, a malformed or foreign-version message (answered, then closed), a live socket never
// taken over, a stale one replaced, and the socket its owner's only.
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "firmware/services/display_link/message_codec.hpp"
#include "firmware/services/display_link/request_server.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil;
using namespace stencil::display_link;

namespace {

struct Folder {
  std::filesystem::path dir;
  Folder() {
    char pattern[] = "/tmp/request-server-tests-XXXXXX";
    dir = mkdtemp(pattern);
  }
  ~Folder() { std::filesystem::remove_all(dir); }
  [[nodiscard]] std::string socket() const { return (dir / "display.sock").string(); }
};

int connect_to(const std::string& path) {
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
  if (connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    close(fd);
    return -1;
  }
  timeval timeout{2, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  return fd;
}

void send_message(int fd, const Message& message) {
  CHECK(send(fd, &message, kMessageBytes, MSG_NOSIGNAL) == static_cast<ssize_t>(kMessageBytes));
}

// One answer (and the descriptor passed with it, or -1); false at end of stream.
bool receive(int fd, Message& message, int* passed = nullptr) {
  iovec part{&message, kMessageBytes};
  msghdr header{};
  header.msg_iov = &part;
  header.msg_iovlen = 1;
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(int))] = {};
  header.msg_control = control;
  header.msg_controllen = sizeof control;
  const ssize_t got = recvmsg(fd, &header, MSG_WAITALL);
  if (passed != nullptr) {
    *passed = -1;
    for (cmsghdr* c = CMSG_FIRSTHDR(&header); c != nullptr; c = CMSG_NXTHDR(&header, c)) {
      if (c->cmsg_type == SCM_RIGHTS) {
        std::memcpy(passed, CMSG_DATA(c), sizeof(int));
      }
    }
  }
  return got == static_cast<ssize_t>(kMessageBytes);
}

std::string limits_refusal(const Request& request) {
  RequestLimits limits;
  return refusal(request, limits);
}

}  // namespace

TEST_GROUP(RequestServer) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(RequestServer, AWelcomedDisplaysAcceptedRequestsReachTheQueueAndRefusalsComeBackWithTheReason) {
  Folder folder;
  const int feed = memfd_create("feed", MFD_CLOEXEC);
  control::CommandRing server_ring;
  RequestServer server({folder.socket()}, feed, limits_refusal, server_ring);
  std::string error;
  CHECK_TRUE_TEXT(server.start(error), error.c_str());
  struct stat st {};
  CHECK(stat(folder.socket().c_str(), &st) == 0);
  CHECK_EQUAL(0600U, st.st_mode & 0777U);
  const int fd = connect_to(folder.socket());
  CHECK(fd >= 0);
  send_message(fd, make_message(MessageKind::Hello, 0));
  Message answer{};
  int passed = -1;
  CHECK(receive(fd, answer, &passed));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Welcome);
  CHECK(passed >= 0);  // the feed, handed over
  close(passed);
  send_message(fd, make_set(Parameter::Coupling, 0.8, 5));
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Accepted);
  CHECK_EQUAL(5U, answer.id);
  send_message(fd, make_set(Parameter::ForceLimit, 50.0, 6));
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Refused);
  STRCMP_CONTAINS("above the board's force limit", reason_of(answer).c_str());
  control::Command command{};
  CHECK(server_ring.pop(command));  // straight into the cycle's ring for the displays
  CHECK(command.kind == control::CommandKind::SetCoupling);
  CHECK(command.source == control::CommandSource::Display);
  DOUBLES_EQUAL(0.8, command.value, 0.0);
  CHECK_FALSE(server_ring.pop(command));
  const RequestCounters counters = server.counters();
  CHECK_EQUAL(1U, counters.accepted);
  CHECK_EQUAL(1U, counters.refused);
  CHECK_EQUAL(1U, counters.displays_seen);
  close(fd);
  server.stop();
  CHECK_FALSE(std::filesystem::exists(folder.socket()));
  close(feed);
}

TEST(RequestServer, MalformedMessagesAndAnotherVersionAreAnsweredThenClosed) {
  Folder folder;
  control::CommandRing server_ring;
  RequestServer server({folder.socket()}, -1, limits_refusal, server_ring);
  std::string error;
  CHECK(server.start(error));
  // A request before Hello.
  int fd = connect_to(folder.socket());
  send_message(fd, make_message(MessageKind::Reset, 3));
  Message answer{};
  CHECK(receive(fd, answer));
  STRCMP_CONTAINS("Hello first", reason_of(answer).c_str());
  CHECK_FALSE(receive(fd, answer));  // closed
  close(fd);
  // Bytes that are not a message.
  fd = connect_to(folder.socket());
  Message junk = make_message(MessageKind::Hello, 0);
  junk.magic = 0xDEADBEEF;
  send_message(fd, junk);
  CHECK(receive(fd, answer));
  STRCMP_CONTAINS("malformed: byte 0", reason_of(answer).c_str());
  CHECK_FALSE(receive(fd, answer));
  close(fd);
  // Another protocol version: both named.
  fd = connect_to(folder.socket());
  Message hello = make_message(MessageKind::Hello, 0);
  hello.version = 9;
  send_message(fd, hello);
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Mismatch);
  STRCMP_CONTAINS(("protocol version 9 from the other side, this side speaks version " + std::to_string(kProtocolVersion)).c_str(), reason_of(answer).c_str());
  CHECK_FALSE(receive(fd, answer));
  close(fd);
  CHECK_EQUAL(3U, server.counters().malformed);
}

TEST(RequestServer, AStopIsNeverRateLimitedAndStopPauseAndResumeReachTheRingAsTheirCommands) {
  Folder folder;
  const int feed = memfd_create("feed", MFD_CLOEXEC);
  control::CommandRing ring;
  RequestServer server({folder.socket(), 8, 10.0, 2.0}, feed, limits_refusal, ring);
  std::string error;
  CHECK(server.start(error));
  const int fd = connect_to(folder.socket());
  send_message(fd, make_message(MessageKind::Hello, 0));
  Message answer{};
  int passed = -1;
  CHECK(receive(fd, answer, &passed));
  close(passed);
  send_message(fd, make_message(MessageKind::Pause, 1));
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Accepted);
  send_message(fd, make_message(MessageKind::Resume, 2));
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Accepted);
  send_message(fd, make_message(MessageKind::Pause, 3));  // past the burst of 2
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Refused);
  for (std::uint32_t id = 4; id < 8; ++id) {  // a stop pressed four times at once: all accepted, one sent
    send_message(fd, make_message(MessageKind::Stop, id));
    CHECK(receive(fd, answer));
    CHECK_TEXT(static_cast<MessageKind>(answer.kind) == MessageKind::Accepted, reason_of(answer).c_str());
  }
  const control::CommandKind expected[] = {control::CommandKind::Pause, control::CommandKind::Resume,
                                           control::CommandKind::Stop};
  for (const control::CommandKind kind : expected) {
    control::Command command{};
    CHECK(ring.pop(command));
    CHECK(command.kind == kind);
    CHECK(command.source == control::CommandSource::Display);
  }
  control::Command more{};
  CHECK_FALSE(ring.pop(more));
  std::this_thread::sleep_for(std::chrono::milliseconds(150));  // a stop pressed again later is sent again
  send_message(fd, make_message(MessageKind::Stop, 8));
  CHECK(receive(fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Accepted);
  CHECK(ring.pop(more));
  CHECK(more.kind == control::CommandKind::Stop);
  control::Command none{};
  CHECK_FALSE(ring.pop(none));
  CHECK_EQUAL(1U, server.counters().rate_limited);
  close(fd);
  close(feed);
}

// A control command's client (stencil-rig stop, ...) says so in its Hello: its commands are recorded as
// from `control`, a display's beside it as from `display`.
TEST(RequestServer, AControlCommandsRequestsAreRecordedAsFromControl) {
  Folder folder;
  const int feed = memfd_create("feed", MFD_CLOEXEC);
  control::CommandRing ring;
  RequestServer server({folder.socket(), 8, 10.0, 5.0}, feed, limits_refusal, ring);
  std::string error;
  CHECK(server.start(error));
  const int command_fd = connect_to(folder.socket());
  Message hello = make_message(MessageKind::Hello, 0);
  hello.parameter = kHelloControl;
  send_message(command_fd, hello);
  Message answer{};
  int passed = -1;
  CHECK(receive(command_fd, answer, &passed));
  close(passed);
  send_message(command_fd, make_message(MessageKind::Pause, 1));
  CHECK(receive(command_fd, answer));
  CHECK(static_cast<MessageKind>(answer.kind) == MessageKind::Accepted);
  const int display_fd = connect_to(folder.socket());
  send_message(display_fd, make_message(MessageKind::Hello, 0));
  CHECK(receive(display_fd, answer, &passed));
  close(passed);
  send_message(display_fd, make_message(MessageKind::Resume, 2));
  CHECK(receive(display_fd, answer));
  control::Command command{};
  CHECK(ring.pop(command));
  CHECK(command.kind == control::CommandKind::Pause);
  CHECK(command.source == control::CommandSource::Control);
  CHECK(ring.pop(command));
  CHECK(command.kind == control::CommandKind::Resume);
  CHECK(command.source == control::CommandSource::Display);
  close(command_fd);
  close(display_fd);
  server.stop();
  close(feed);
}

TEST(RequestServer, ADisplaySendingTooFastIsRefusedPastItsBurst) {
  Folder folder;
  const int feed = memfd_create("feed", MFD_CLOEXEC);
  control::CommandRing server_ring;
  RequestServer server({folder.socket(), 8, 10.0, 5.0}, feed, limits_refusal, server_ring);
  std::string error;
  CHECK(server.start(error));
  const int fd = connect_to(folder.socket());
  send_message(fd, make_message(MessageKind::Hello, 0));
  Message answer{};
  int passed = -1;
  CHECK(receive(fd, answer, &passed));
  close(passed);
  int accepted = 0, limited = 0;
  for (std::uint32_t i = 0; i < 20; ++i) {
    send_message(fd, make_set(Parameter::Coupling, 0.5, i));
    CHECK(receive(fd, answer));
    accepted += static_cast<MessageKind>(answer.kind) == MessageKind::Accepted ? 1 : 0;
    limited += reason_of(answer).find("too many requests: at most 10 a second") != std::string::npos ? 1 : 0;
  }
  CHECK(accepted >= 5 && accepted <= 7);  // the burst, and what the rate refilled meanwhile
  CHECK_EQUAL(20 - accepted, limited);
  CHECK_EQUAL(static_cast<std::uint64_t>(limited), server.counters().rate_limited);
  close(fd);
  close(feed);
}

TEST(RequestServer, ALiveSocketIsNeverTakenOverAndAStaleOneIsReplaced) {
  Folder folder;
  control::CommandRing first_ring;
  RequestServer first({folder.socket()}, -1, limits_refusal, first_ring);
  std::string error;
  CHECK(first.start(error));
  control::CommandRing second_ring;
  RequestServer second({folder.socket()}, -1, limits_refusal, second_ring);
  CHECK_FALSE(second.start(error));
  STRCMP_CONTAINS("another controller is serving displays there", error.c_str());
  // A socket left by a controller that died: nobody answers it.
  const std::string stale = (folder.dir / "stale.sock").string();
  {
    const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, stale.c_str(), sizeof address.sun_path - 1);
    CHECK(bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0);
    close(fd);
  }
  control::CommandRing third_ring;
  RequestServer third({stale}, -1, limits_refusal, third_ring);
  CHECK_TRUE_TEXT(third.start(error), error.c_str());
  // Something that is not a socket is never removed.
  const std::string file = (folder.dir / "file").string();
  std::FILE* f = std::fopen(file.c_str(), "w");
  std::fclose(f);
  control::CommandRing fourth_ring;
  RequestServer fourth({file}, -1, limits_refusal, fourth_ring);
  CHECK_FALSE(fourth.start(error));
  STRCMP_CONTAINS("is not a socket", error.c_str());
  CHECK(std::filesystem::exists(file));
}

TEST(RequestServer, DisplaysBeyondTheLimitAreClosedAtOnce) {
  Folder folder;
  const int feed = memfd_create("feed", MFD_CLOEXEC);
  control::CommandRing server_ring;
  RequestServer server({folder.socket(), 2}, feed, limits_refusal, server_ring);
  std::string error;
  CHECK(server.start(error));
  const int a = connect_to(folder.socket());
  const int b = connect_to(folder.socket());
  const int c = connect_to(folder.socket());
  Message answer{};
  CHECK_FALSE(receive(c, answer));  // closed without a word
  send_message(a, make_message(MessageKind::Hello, 0));
  int passed = -1;
  CHECK(receive(a, answer, &passed));
  CHECK_EQUAL(1U, server.counters().peers_refused);
  CHECK_EQUAL(2U, server.counters().displays_connected);
  close(passed);
  for (const int fd : {a, b, c, feed}) {
    close(fd);
  }
}
