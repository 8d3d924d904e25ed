// The whole link in one process: a controller's DisplayLink fed as the boards feed it, and a
// display's ControllerClient that connects, maps the feed, sends requests and sees the job end.
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/display_link/controller_client.hpp"
#include "firmware/services/display_link/display_link.hpp"
#include "firmware/services/display_link/message_codec.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil;
using namespace stencil::display_link;

namespace {

struct Prism {
  tablegen::TableBytes bytes = test::make_table(test::default_part(), test::default_job_options(2));
  tables::PartTables part{};
  Prism() { CHECK(tables::load_tables({bytes.data(), bytes.size()}, part).ok); }
};

control::ControllerConfig config() {
  control::ControllerConfig c;
  c.frames = {10.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(25.0, 12.5, 20.0), {-1, -1, 1}, 640.0};
  c.max_axis_move_mm = 1e-3;
  c.max_total_move_mm = 1e-3;
  return c;
}

struct Folder {
  std::filesystem::path dir;
  Folder() {
    char pattern[] = "/tmp/display-link-tests-XXXXXX";
    dir = mkdtemp(pattern);
  }
  ~Folder() { std::filesystem::remove_all(dir); }
  [[nodiscard]] std::string socket() const { return (dir / "display.sock").string(); }
};

control::JournalRecord record_at(std::uint64_t cycle, const Eigen::Vector3d& tip, std::uint32_t touched) {
  control::JournalRecord r{};
  r.cycle = cycle;
  r.time_ns = static_cast<std::int64_t>(cycle) * 1'000'000;
  for (int i = 0; i < 3; ++i) {
    r.virtual_tip_mm[i] = tip[i];
    r.device_mm[i] = 10.0 * tip[i];
  }
  r.touched_triangles = touched;
  r.force_n[2] = static_cast<float>(cycle % 7);
  return r;
}

// Polls until `done` or 3 s; the answers it heard.
template <typename Done>
std::vector<Message> poll_until(ControllerClient& client, Done done) {
  std::vector<Message> answers;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (!done(answers) && std::chrono::steady_clock::now() < until) {
    client.poll(answers, 10);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return answers;
}

}  // namespace

TEST_GROUP(DisplayLink) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(DisplayLink, ADisplayWaitsForItsControllerThenSeesItsState) {
  Prism prism;
  Folder folder;
  ControllerClient client(folder.socket());
  std::vector<Message> answers;
  client.poll(answers, 0);
  CHECK(client.state() == LinkState::Waiting);
  STRCMP_CONTAINS("no controller at", client.detail().c_str());
  CHECK(client.feed() == nullptr);

  DisplayLink link(prism.part, config(), {folder.socket(), "stencil-test", true});
  std::string error;
  CHECK_TRUE_TEXT(link.start(error), error.c_str());
  poll_until(client, [&](const auto&) { return client.state() == LinkState::Connected; });
  CHECK(client.state() == LinkState::Connected);
  STRCMP_CONTAINS("stencil-test (pid", client.detail().c_str());
  const FeedView* feed = client.feed();
  CHECK(feed != nullptr);
  CHECK_EQUAL(1U, client.feed_generation());
  CHECK_EQUAL(prism.part.triangle_count(), feed->header().triangle_count);
  CHECK_EQUAL(1, feed->header().virtual_clock);

  // Far above the prism, then on its top face (the cycle's count grew): the mirror marks there too.
  link.on_record(record_at(1, Eigen::Vector3d(25.0, 12.5, 20.0), 0));
  link.on_record(record_at(2, Eigen::Vector3d(25.0, 12.5, 6.0), 1));
  control::Telemetry t{};
  t.cycle = 2;
  t.wakeup_ns = 25'000;
  link.on_telemetry(t);
  link.end("still running");  // publishes now (else at most every millisecond)
  Figures figures{};
  CHECK(feed->read(figures));
  CHECK_EQUAL(2U, figures.cycle);
  CHECK(figures.touched_count >= 1U);
  CHECK(figures.reachable_touched >= 1U);
  CHECK_EQUAL(1U, figures.wakeup.counts[2]);  // 25 us: the third 10 us bin
  const Eigen::Vector3d probe = motion::device_to_world(config().frames, Eigen::Vector3d(250.0, 125.0, 60.0));
  DOUBLES_EQUAL(probe.x(), figures.probe_mm[0], 1e-9);
  std::vector<std::uint8_t> bits;
  feed->touched(bits);
  std::uint32_t set = 0;
  for (const std::uint8_t byte : bits) {
    set += static_cast<std::uint32_t>(__builtin_popcount(byte));
  }
  CHECK_EQUAL(figures.touched_count, set);
  DOUBLES_EQUAL(2.0, feed->force_peak(0, 2), 0.0);
}

TEST(DisplayLink, RequestsAreDecidedOnTheControllersSideAndAcceptedOnesReachTheCycle) {
  Prism prism;
  Folder folder;
  DisplayLink link(prism.part, config(), {folder.socket(), "stencil-test", false});
  std::string error;
  CHECK(link.start(error));
  ControllerClient client(folder.socket());
  poll_until(client, [&](const auto&) { return client.state() == LinkState::Connected; });
  // A reset outside the safe state: refused with the reason; then in one, with the handle still and
  // near: accepted, and the cycle's command is waiting.
  CHECK(client.send(make_message(MessageKind::Reset, 1)));
  std::vector<Message> answers = poll_until(client, [](const auto& a) { return !a.empty(); });
  CHECK_EQUAL(1U, answers.size());
  CHECK(static_cast<MessageKind>(answers[0].kind) == MessageKind::Refused);
  STRCMP_EQUAL("not in a safe state", reason_of(answers[0]).c_str());
  control::Telemetry t{};
  t.cycle = 1;
  t.safe_reason = control::SafeReason::DeviceStale;
  t.device_still_s = 10.0;
  t.device_to_tool_mm = 0.5;
  link.on_telemetry(t);
  link.end("publish");
  CHECK(client.send(make_message(MessageKind::Reset, 2)));
  CHECK(client.send(make_set(Parameter::Coupling, 99.0, 3)));
  answers = poll_until(client, [](const auto& a) { return a.size() >= 2; });
  CHECK_EQUAL(2U, answers.size());
  CHECK(static_cast<MessageKind>(answers[0].kind) == MessageKind::Accepted);
  CHECK(static_cast<MessageKind>(answers[1].kind) == MessageKind::Refused);
  STRCMP_CONTAINS("outside the coupling's range", reason_of(answers[1]).c_str());
  control::Command command{};
  CHECK(link.commands().pop(command));
  CHECK(command.kind == control::CommandKind::Reset);
  CHECK_FALSE(link.commands().pop(command));
}

TEST(DisplayLink, WhenTheControllerEndsTheDisplayKeepsItsLastStateAndSaysHow) {
  Prism prism;
  Folder folder;
  ControllerClient client(folder.socket());
  {
    DisplayLink link(prism.part, config(), {folder.socket(), "stencil-test", false});
    std::string error;
    CHECK(link.start(error));
    poll_until(client, [&](const auto&) { return client.state() == LinkState::Connected; });
    link.on_record(record_at(41, Eigen::Vector3d(25.0, 12.5, 20.0), 0));
    link.end("the job ended after 41 cycles");
    link.stop();
  }
  poll_until(client, [&](const auto&) { return client.state() == LinkState::Ended; });
  CHECK(client.state() == LinkState::Ended);
  const FeedView* feed = client.feed();
  CHECK(feed != nullptr);  // the mapping outlives the controller
  Figures figures{};
  CHECK(feed->read(figures));
  CHECK(figures.phase == JobPhase::Ended);
  STRCMP_EQUAL("the job ended after 41 cycles", figures.end_text);
  CHECK_EQUAL(41U, figures.cycle);
  // A new controller on the same socket: a new feed.
  DisplayLink next(prism.part, config(), {folder.socket(), "stencil-next", false});
  std::string error;
  CHECK(next.start(error));
  poll_until(client, [&](const auto&) { return client.state() == LinkState::Connected; });
  CHECK_EQUAL(2U, client.feed_generation());
  STRCMP_EQUAL("stencil-next", client.feed()->header().program);
}
