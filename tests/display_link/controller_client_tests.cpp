// ControllerClient (controller_client.hpp), a display's end of the link, against a controller played
// by the test on a real Unix socket: it waits (retrying no more often than asked) while there is none,
// says hello as a display or a control command, is welcomed only with a feed, passes requests and
// answers, is refused with the controller's reason, and keeps the last feed once the controller ends.
// (The whole link, DisplayLink to ControllerClient, is display_link_tests.cpp's.)
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/display_link/controller_client.hpp"
#include "firmware/services/display_link/message_codec.hpp"
#include "firmware/services/display_link/state_feed.hpp"
#include "tests/support/sample_tables.hpp"
#include "tests/support/temp_folder.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil;
using namespace stencil::display_link;

namespace {

// A controller as far as the socket goes: it listens, accepts, reads a message, sends one (with a
// descriptor when given).
struct FakeController {
  int listener = -1;
  int peer = -1;
  explicit FakeController(const std::string& path) {
    listener = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
    CHECK(bind(listener, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0);
    CHECK(listen(listener, 4) == 0);
  }
  ~FakeController() {
    hang_up();
    close(listener);
  }
  FakeController(const FakeController&) = delete;
  FakeController& operator=(const FakeController&) = delete;
  // False when no display has connected (a display's connect() is done by the time it returns).
  bool accept_one() {
    peer = accept4(listener, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    return peer >= 0;
  }
  bool receive(Message& message) {
    for (int i = 0; i < 200; ++i) {
      if (recv(peer, &message, kMessageBytes, MSG_WAITALL) == static_cast<ssize_t>(kMessageBytes)) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }
  void send_message(const Message& message, int fd = -1) {
    iovec part{const_cast<Message*>(&message), kMessageBytes};
    msghdr header{};
    header.msg_iov = &part;
    header.msg_iovlen = 1;
    alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(int))] = {};
    if (fd >= 0) {
      header.msg_control = control;
      header.msg_controllen = sizeof control;
      cmsghdr* c = CMSG_FIRSTHDR(&header);
      c->cmsg_level = SOL_SOCKET;
      c->cmsg_type = SCM_RIGHTS;
      c->cmsg_len = CMSG_LEN(sizeof(int));
      std::memcpy(CMSG_DATA(c), &fd, sizeof(int));
    }
    CHECK(sendmsg(peer, &header, MSG_NOSIGNAL) == static_cast<ssize_t>(kMessageBytes));
  }
  void hang_up() {
    if (peer >= 0) {
      close(peer);
      peer = -1;
    }
  }
};

// Polls until `client` is in `state` (a second at most).
bool poll_until(ControllerClient& client, LinkState state, std::vector<Message>& answers) {
  for (int i = 0; i < 200 && client.state() != state; ++i) {
    client.poll(answers, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return client.state() == state;
}

struct Prism {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  Prism() { CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok); }
};

}  // namespace

TEST_GROUP(ControllerClient) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(ControllerClient, EachLinkStateHasTheNameThePageShows) {
  STRCMP_EQUAL("waiting", link_state_name(LinkState::Waiting));
  STRCMP_EQUAL("connected", link_state_name(LinkState::Connected));
  STRCMP_EQUAL("ended", link_state_name(LinkState::Ended));
  STRCMP_EQUAL("refused", link_state_name(LinkState::Refused));
}

TEST(ControllerClient, WithNoControllerItWaitsSaysWhyAndTakesNoRequest) {
  testing::TempFolder folder("controller-client-tests");
  ControllerClient client(folder.file("display.sock"));
  CHECK(client.state() == LinkState::Waiting);
  STRCMP_EQUAL(("no controller at " + folder.file("display.sock") + " yet: waiting for one").c_str(), client.detail().c_str());
  std::vector<Message> answers;
  client.poll(answers, 0);
  CHECK(client.state() == LinkState::Waiting);
  STRCMP_CONTAINS("(No such file or directory): waiting for one", client.detail().c_str());
  CHECK_FALSE(client.send(make_message(MessageKind::Reset, 1)));
  CHECK(client.feed() == nullptr);
  LONGS_EQUAL(0, client.feed_generation());
  CHECK(answers.empty());

  ControllerClient too_long(std::string(200, 's'));
  too_long.poll(answers, 0);
  CHECK(too_long.state() == LinkState::Refused);
  STRCMP_CONTAINS("is too long for a Unix socket", too_long.detail().c_str());
}

// The display's tick polls many times a second; a missing controller is looked for only every
// retry_ms.
TEST(ControllerClient, AMissingControllerIsLookedForNoMoreOftenThanAsked) {
  testing::TempFolder folder("controller-client-tests");
  ControllerClient client(folder.file("display.sock"));
  std::vector<Message> answers;
  client.poll(answers, 60'000);  // looks now: none
  FakeController controller(folder.file("display.sock"));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  client.poll(answers, 60'000);  // not again for a minute
  CHECK_FALSE(controller.accept_one());
  CHECK(client.state() == LinkState::Waiting);
  ControllerClient eager(folder.file("display.sock"));
  eager.poll(answers, 60'000);  // its first look
  CHECK_TRUE(controller.accept_one());
}

TEST(ControllerClient, WelcomedWithAFeedItIsConnectedPassesRequestsAndAnswersAndKeepsTheFeedWhenTheControllerEnds) {
  testing::TempFolder folder("controller-client-tests");
  FakeController controller(folder.file("display.sock"));
  Prism prism;
  FeedWriter feed;
  FeedFacts facts;
  facts.program = "stencil-fake";
  std::string error;
  CHECK_TRUE_TEXT(feed.create(prism.part, facts, error), error.c_str());

  ControllerClient client(folder.file("display.sock"));
  std::vector<Message> answers;
  client.poll(answers, 0);
  CHECK_TRUE(controller.accept_one());
  Message hello{};
  CHECK_TRUE(controller.receive(hello));
  CHECK(static_cast<MessageKind>(hello.kind) == MessageKind::Hello);
  LONGS_EQUAL(kHelloDisplay, hello.parameter);
  CHECK(client.state() == LinkState::Waiting);  // connected, not yet welcomed
  CHECK_FALSE(client.send(make_message(MessageKind::Reset, 1)));

  controller.send_message(make_message(MessageKind::Welcome, 0), feed.fd());
  CHECK_TRUE(poll_until(client, LinkState::Connected, answers));
  STRCMP_EQUAL(("stencil-fake (pid " + std::to_string(getpid()) + ") at " + folder.file("display.sock")).c_str(),
               client.detail().c_str());
  LONGS_EQUAL(1, client.feed_generation());
  CHECK(client.feed() != nullptr);
  LONGS_EQUAL(prism.part.triangle_count(), client.feed()->header().triangle_count);

  CHECK_TRUE(client.send(make_set(Parameter::Coupling, 0.5, 7)));
  Message asked{};
  CHECK_TRUE(controller.receive(asked));
  CHECK(static_cast<MessageKind>(asked.kind) == MessageKind::Set);
  LONGS_EQUAL(7, asked.id);
  controller.send_message(make_answer(MessageKind::Refused, 7, "not now"));
  for (int i = 0; i < 200 && answers.empty(); ++i) {
    client.poll(answers, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  LONGS_EQUAL(1, answers.size());
  LONGS_EQUAL(7, answers[0].id);
  STRCMP_EQUAL("not now", reason_of(answers[0]).c_str());

  controller.hang_up();
  CHECK_TRUE(poll_until(client, LinkState::Ended, answers));
  STRCMP_EQUAL("the controller ended", client.detail().c_str());
  CHECK(client.feed() != nullptr);  // the last state stays on the page
  CHECK_FALSE(client.send(make_message(MessageKind::Reset, 2)));
}

// A control command (stencil-rig stop) says so in its Hello; a controller of another version, or a
// Welcome without its feed, is a refusal that says why.
TEST(ControllerClient, AControlClientSaysSoAndAMismatchOrAWelcomeWithoutAFeedIsARefusalSayingWhy) {
  testing::TempFolder folder("controller-client-tests");
  FakeController controller(folder.file("display.sock"));
  std::vector<Message> answers;
  {
    ControllerClient control(folder.file("display.sock"), true);
    control.poll(answers, 0);
    CHECK_TRUE(controller.accept_one());
    Message hello{};
    CHECK_TRUE(controller.receive(hello));
    LONGS_EQUAL(kHelloControl, hello.parameter);
    controller.send_message(make_answer(MessageKind::Mismatch, 0, "controller version 9, display version 3"));
    CHECK_TRUE(poll_until(control, LinkState::Refused, answers));
    STRCMP_EQUAL(("the controller at " + folder.file("display.sock") +
                  " refused this display: controller version 9, display version 3")
                     .c_str(),
                 control.detail().c_str());
    controller.hang_up();
  }
  ControllerClient client(folder.file("display.sock"));
  client.poll(answers, 0);
  CHECK_TRUE(controller.accept_one());
  controller.send_message(make_message(MessageKind::Welcome, 0));  // no descriptor
  CHECK_TRUE(poll_until(client, LinkState::Refused, answers));
  STRCMP_EQUAL("the controller's Welcome came without its state feed", client.detail().c_str());
  CHECK(client.feed() == nullptr);
  CHECK(answers.empty());
}
