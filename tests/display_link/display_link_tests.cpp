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

// A controller's link, started, with a display connected to it.
struct Connected {
  Prism prism;
  Folder folder;
  DisplayLink link{prism.part, config(), {folder.socket(), "stencil-test", false}};
  ControllerClient client{folder.socket()};
  Connected() {
    std::string error;
    CHECK_TRUE_TEXT(link.start(error), error.c_str());
    poll_until(client, [&](const auto&) { return client.state() == LinkState::Connected; });
  }
};

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
  Connected connected;
  DisplayLink& link = connected.link;
  ControllerClient& client = connected.client;
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
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  link.on_telemetry(t);  // past the 1 ms between publications: this one goes out
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

// The spindle's start through the link (a service has no terminal): refused unless the program is
// waiting for it, then taken once by the program, never as a cycle command; a stop ends the wait.
TEST(DisplayLink, AStartIsTakenOnceByTheWaitingProgramAndAStopEndsTheWait) {
  Connected connected;
  DisplayLink& link = connected.link;
  ControllerClient& client = connected.client;
  CHECK(client.send(make_message(MessageKind::Start, 1)));
  std::vector<Message> answers = poll_until(client, [](const auto& a) { return !a.empty(); });
  CHECK_EQUAL(1U, answers.size());
  CHECK(static_cast<MessageKind>(answers[0].kind) == MessageKind::Refused);
  STRCMP_CONTAINS("not waiting for a start", reason_of(answers[0]).c_str());
  using Answer = DisplayLink::StartAnswer;
  CHECK(link.start_answer() == Answer::None);

  link.await_start();
  CHECK(link.start_answer() == Answer::None);
  CHECK(client.send(make_message(MessageKind::Start, 2)));
  CHECK(client.send(make_message(MessageKind::Start, 3)));
  answers = poll_until(client, [](const auto& a) { return a.size() >= 2; });
  CHECK_EQUAL(2U, answers.size());
  CHECK(static_cast<MessageKind>(answers[0].kind) == MessageKind::Accepted);
  CHECK(static_cast<MessageKind>(answers[1].kind) == MessageKind::Refused);  // once only
  CHECK(link.start_answer() == Answer::Start);
  CHECK(link.end_start_wait() == Answer::Start);
  CHECK(link.start_answer() == Answer::None);  // the wait is over
  control::Command command{};
  CHECK_FALSE(link.commands().pop(command));

  // A stop while the start is awaited ends the wait: nothing is cut (and it reaches the ring as ever).
  link.await_start();
  CHECK(client.send(make_message(MessageKind::Stop, 4)));
  answers = poll_until(client, [](const auto& a) { return !a.empty(); });
  CHECK_EQUAL(1U, answers.size());
  CHECK(static_cast<MessageKind>(answers[0].kind) == MessageKind::Accepted);
  CHECK(link.end_start_wait() == Answer::Stop);
  CHECK(link.commands().pop(command));
  CHECK(command.kind == control::CommandKind::Stop);
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

// Issue 22: the feed carries the event list (each command taken, each safe state with its source)
// and the position readout (the record's device and tool, the machine thread's mill).
TEST(DisplayLink, TheFeedCarriesTheEventsAndThePositionsTheReadoutShows) {
  Prism prism;
  Folder folder;
  DisplayLink link(prism.part, config(), {folder.socket(), "stencil-test", false});
  std::string error;
  CHECK_TRUE_TEXT(link.start(error), error.c_str());
  ControllerClient client(folder.socket());
  poll_until(client, [&](const auto&) { return client.feed() != nullptr; });
  const FeedView* feed = client.feed();
  CHECK(feed != nullptr);
  FeedMachine machine{};
  CHECK(feed->read(machine));
  DOUBLES_EQUAL(25.0, machine.work_mm[0], 0.0);  // at home until the first update
  DOUBLES_EQUAL(0.0, machine.machine_mm[0], 0.0);

  link.on_command({7, 7'000'000, 6, control::CommandKind::SetForceLimit, control::CommandSource::Display,
                   control::CommandOutcome::Clamped, 50.0, 5.0});
  control::JournalRecord stopped = record_at(9, Eigen::Vector3d(26.0, 12.0, 19.5), 0);
  stopped.safe_reason = control::SafeReason::Stopped;
  stopped.safe_source = control::CommandSource::Signal;
  link.on_record(stopped);
  link.on_record(record_at(10, Eigen::Vector3d(26.0, 12.0, 19.5), 0));  // reset: no event of its own
  const control::StockBlock block{{20.0, 8.0, 0.0}, {30.0, 16.0, 7.0}};
  std::vector<float> cells(control::CommandedStock::cells_needed(block, 0.5));
  const control::CommandedStock model(block, 0.5, prism.part.tool.spec, cells);
  link.on_machine({0.01, {25.5, 12.25, 19.75}, true}, model);
  link.end("test");
  Figures figures{};
  CHECK(feed->read(figures));
  CHECK_EQUAL(2U, figures.events_total);
  CHECK(figures.events[0].type == FeedEventType::Command);
  CHECK(figures.events[0].kind == control::CommandKind::SetForceLimit);
  CHECK(figures.events[0].outcome == control::CommandOutcome::Clamped);
  DOUBLES_EQUAL(5.0, figures.events[0].applied, 0.0);
  CHECK(figures.events[1].type == FeedEventType::SafeState);
  CHECK(figures.events[1].reason == control::SafeReason::Stopped);
  CHECK(figures.events[1].source == control::CommandSource::Signal);
  LONGS_EQUAL(9, figures.events[1].cycle);
  DOUBLES_EQUAL(260.0, figures.device_mm[0], 1e-12);
  DOUBLES_EQUAL(-1.0, figures.virtual_machine_mm[0], 1e-12);  // x counts against the world's
  DOUBLES_EQUAL(-0.5, figures.virtual_machine_mm[2], 1e-12);
  CHECK(feed->read(machine));
  DOUBLES_EQUAL(25.5, machine.work_mm[0], 0.0);
  DOUBLES_EQUAL(-0.5, machine.machine_mm[0], 1e-12);
  DOUBLES_EQUAL(0.25, machine.machine_mm[1], 1e-12);
  DOUBLES_EQUAL(-0.25, machine.machine_mm[2], 1e-12);
  CHECK_EQUAL(1U, machine.held);
}
