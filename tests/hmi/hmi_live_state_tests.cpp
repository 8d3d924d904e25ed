// The operator display's own rules and state (stencil-display): its endpoint and token rules, the
// request parser and the limits it checks, and the live state built from a controller's feed
// (through a real DisplayLink): deltas and snapshots, the stock, the reset rule, the job's end; and
// the display's handling of a browser's requests before they go to the controller.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/display_link/display_link.hpp"
#include "firmware/services/hmi/display_app.hpp"
#include "firmware/services/hmi/hmi_access.hpp"
#include "firmware/services/hmi/hmi_live_state.hpp"
#include "firmware/services/hmi/hmi_requests.hpp"
#include "tests/support/sample_tables.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil;
using namespace stencil::hmi;

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
    char pattern[] = "/tmp/hmi-tests-XXXXXX";
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
  return r;
}

// A controller's link and a display's view of its feed, in one process: what the boards feed the
// link is what the live state reads (published at once: end() publishes without the rate limit).
struct Linked {
  Folder folder;
  display_link::DisplayLink link;
  display_link::FeedView view;
  LiveState state;
  Linked(const tables::PartTables& part, const control::ControllerConfig& c)
      : link(part, c, {folder.socket(), "stencil-test", false}) {
    std::string error;
    CHECK_TRUE_TEXT(link.start(error), error.c_str());
    CHECK_TRUE_TEXT(view.open(dup(link.feed_fd()), error), error.c_str());
  }
  void publish() {
    link.end("");  // publishes now; a phase of Ended is only shown, never acted on here
    state.update(&view, 1);
  }
};

}  // namespace

TEST_GROUP(HmiAccess){};

TEST(HmiAccess, EndpointsAreParsedAndBadOnesNamed) {
  HmiEndpoint e;
  std::string error;
  CHECK(parse_endpoint("", e, error));
  STRCMP_EQUAL("127.0.0.1", e.host.c_str());
  CHECK_EQUAL(8080, e.port);
  CHECK(parse_endpoint("0.0.0.0:9000", e, error));
  STRCMP_EQUAL("0.0.0.0", e.host.c_str());
  CHECK_EQUAL(9000, e.port);
  CHECK(parse_endpoint("[::1]:81", e, error));
  STRCMP_EQUAL("::1", e.host.c_str());
  CHECK(parse_endpoint("localhost:0", e, error));
  STRCMP_EQUAL("127.0.0.1", e.host.c_str());
  CHECK_FALSE(parse_endpoint("127.0.0.1", e, error));
  CHECK(error.find("HOST:PORT") != std::string::npos);
  CHECK_FALSE(parse_endpoint("127.0.0.1:70000", e, error));
  CHECK(error.find("0 to 65535") != std::string::npos);
  CHECK_FALSE(parse_endpoint("127.0.0.1:80x", e, error));
  CHECK_FALSE(parse_endpoint("example.com:80", e, error));
  CHECK(error.find("numeric") != std::string::npos);
  CHECK_FALSE(parse_endpoint("[::1:80", e, error));
}

TEST(HmiAccess, BeyondLoopbackATokenIsNeededAndOnlyItsHolderMayControl) {
  std::string error;
  CHECK(check_access({"127.0.0.1", 8080}, "", error));
  CHECK(check_access({"::1", 8080}, "", error));
  CHECK_FALSE(check_access({"0.0.0.0", 8080}, "", error));
  CHECK(error.find("needs a token, from a file only its owner reads") != std::string::npos);
  CHECK_FALSE(check_access({"192.168.1.5", 8080}, "", error));
  CHECK(check_access({"0.0.0.0", 8080}, "s3cret-token", error));
  CHECK_FALSE(check_access({"0.0.0.0", 8080}, "short", error));
  CHECK_FALSE(check_access({"0.0.0.0", 8080}, "has space in it", error));
  CHECK(is_loopback("127.3.4.5"));
  CHECK_FALSE(is_loopback("128.0.0.1"));
  CHECK_FALSE(is_loopback("::2"));

  CHECK(may_control("", ""));  // loopback, no token set: the operator at the machine
  CHECK(may_control("s3cret-token", "s3cret-token"));
  CHECK_FALSE(may_control("s3cret-token", ""));
  CHECK_FALSE(may_control("s3cret-token", "s3cret-toke"));
  CHECK_FALSE(may_control("s3cret-token", "s3cret-tokenX"));
  CHECK_FALSE(may_control("s3cret-token", "S3cret-token"));
}

TEST(HmiAccess, OnlyThisServersOwnPageMayOpenTheSocket) {
  CHECK(same_origin("http://127.0.0.1:8080", "127.0.0.1:8080"));
  CHECK(same_origin("https://rig:8443", "rig:8443"));
  CHECK_FALSE(same_origin("http://evil.example", "127.0.0.1:8080"));
  CHECK_FALSE(same_origin("http://127.0.0.1:8081", "127.0.0.1:8080"));
  CHECK_FALSE(same_origin("http://127.0.0.1:8080.evil", "127.0.0.1:8080"));
  CHECK_FALSE(same_origin("null", "127.0.0.1:8080"));
  CHECK_FALSE(same_origin("http://127.0.0.1:8080", ""));
}

TEST_GROUP(HmiRequests){};

TEST(HmiRequests, WellFormedRequestsAreParsed) {
  Request r;
  std::string error;
  CHECK(parse_request(R"({"type":"set","name":"force_limit","value":2.5})", r, error));
  CHECK(r.kind == RequestKind::Set);
  CHECK(r.parameter == Parameter::ForceLimit);
  DOUBLES_EQUAL(2.5, r.value, 0.0);
  CHECK(command_kind(r.parameter) == control::CommandKind::SetForceLimit);
  CHECK(parse_request(R"({"type":"set","name":"coupling","value":1})", r, error));
  CHECK(r.parameter == Parameter::Coupling);
  CHECK(parse_request(R"({"type":"reset"})", r, error));
  CHECK(r.kind == RequestKind::Reset);
}

TEST(HmiRequests, MalformedMessagesAreRefusedWithWhatWasExpected) {
  Request r;
  std::string error;
  const char* const bad[] = {
      "", "not json", "{", "[]", "42", R"({"type":7})", R"({"kind":"reset"})", R"({"type":"launch"})",
      R"({"type":"set"})", R"({"type":"set","name":"torque","value":1})", R"({"type":"set","name":"coupling"})",
      R"({"type":"set","name":"coupling","value":"1"})", R"({"type":"set","name":"coupling","value":null})",
      "\xff\xfe\x00garbage",
  };
  for (const char* text : bad) {
    error.clear();
    CHECK_FALSE_TEXT(parse_request(text, r, error), text);
    CHECK_TEXT(!error.empty(), text);
  }
  CHECK_FALSE(parse_request(R"({"type":"launch"})", r, error));
  CHECK(error.find("expected \"set\", \"reset\", \"stop\", \"pause\" or \"resume\"") != std::string::npos);
  // Stop, pause and resume are requests of their own.
  CHECK(parse_request(R"({"type":"stop"})", r, error));
  CHECK(r.kind == RequestKind::Stop);
  CHECK(parse_request(R"({"type":"pause"})", r, error));
  CHECK(r.kind == RequestKind::Pause);
  CHECK(parse_request(R"({"type":"resume"})", r, error));
  CHECK(r.kind == RequestKind::Resume);
  const std::string huge = R"({"type":"reset","pad":")" + std::string(2000, 'x') + "\"}";
  CHECK_FALSE(parse_request(huge, r, error));
  CHECK(error.find("at most 1024") != std::string::npos);
}

TEST(HmiRequests, ParametersBeyondTheBoardsLimitsAreRefusedWithTheReason) {
  const HmiLimits limits{5.0, 1.0, 0.05, 2.0};
  CHECK(refusal({RequestKind::Set, Parameter::ForceLimit, 5.0}, limits).empty());
  CHECK(refusal({RequestKind::Set, Parameter::ForceLimit, 0.5}, limits).empty());
  const std::string fifty = refusal({RequestKind::Set, Parameter::ForceLimit, 50.0}, limits);
  STRCMP_CONTAINS("50 N is above the board's force limit of 5 N", fifty.c_str());
  STRCMP_CONTAINS("above what the mill follows, 1 mm/s", refusal({RequestKind::Set, Parameter::SpeedLimit, 2.0}, limits).c_str());
  CHECK(refusal({RequestKind::Set, Parameter::SpeedLimit, 0.5}, limits).empty());
  STRCMP_CONTAINS("outside the coupling's range of 0.05 to 2 N/mm",
                  refusal({RequestKind::Set, Parameter::Coupling, 3.0}, limits).c_str());
  STRCMP_CONTAINS("must be a positive number", refusal({RequestKind::Set, Parameter::Coupling, -1.0}, limits).c_str());
  STRCMP_CONTAINS("must be a positive number",
                  refusal({RequestKind::Set, Parameter::ForceLimit, std::nan("")}, limits).c_str());
  CHECK(refusal({RequestKind::Reset, Parameter::Coupling, 0.0}, limits).empty());
}

TEST_GROUP(HmiLiveState) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(HmiLiveState, WithoutAControllerTheDisplaySaysItIsWaiting) {
  LiveState state;
  state.set_link(display_link::LinkState::Waiting, "no controller at /run/x.sock: waiting for one");
  state.update(nullptr, 0);
  const nlohmann::json frame = state.frame(1, nlohmann::json::object());
  STRCMP_EQUAL("waiting", frame["type"].get<std::string>().c_str());
  STRCMP_CONTAINS("no controller", frame["controller"]["detail"].get<std::string>().c_str());
  STRCMP_EQUAL("waiting", state.snapshot(1, nlohmann::json::object())["type"].get<std::string>().c_str());
  CHECK(state.part_json().empty());
  STRCMP_EQUAL("no controller", state.reset_refusal().c_str());
}

// With a standoff the virtual tool stays that far off the part, and the cycle counts a triangle
// touched within the tolerance beyond it: the display's mirror must mark the same way, or it never
// sees a triangle touched (its coverage stuck at 0 while the cycle's grew).
TEST(HmiLiveState, WithAStandoffTheMirrorMarksWhereTheCycleDoes) {
  Prism prism;
  control::ControllerConfig c = config();
  c.standoff_mm = 0.015;
  Linked linked(prism.part, c);
  // Resting on the top face (z = 6) the standoff over it, as the cycle leaves the virtual tool.
  linked.link.on_record(record_at(1, Eigen::Vector3d(25.0, 12.5, 6.0 + 0.015 + 0.001), 1));
  linked.publish();
  CHECK(linked.state.touched_count() >= 1U);
}

TEST(HmiLiveState, TheTouchedSetIsMirroredFromTheRecordsAndSentAsDeltasThenWhole) {
  Prism prism;
  Linked linked(prism.part, config());
  LiveState& state = linked.state;
  const nlohmann::json server = nlohmann::json::object();
  // Far above the prism: nothing touched.
  linked.link.on_record(record_at(1, Eigen::Vector3d(25.0, 12.5, 20.0), 0));
  linked.publish();
  nlohmann::json first = state.frame(1, server);
  STRCMP_EQUAL("frame", first["type"].get<std::string>().c_str());
  CHECK_EQUAL(0U, first["touched"].size());
  // On its top face (z = 6): the cycle's count grew, so the mirror marks there too.
  linked.link.on_record(record_at(2, Eigen::Vector3d(25.0, 12.5, 6.0), 1));
  linked.publish();
  nlohmann::json second = state.frame(2, server);
  CHECK(second["touched"].size() >= 1U);
  CHECK_EQUAL(second["touched"].size(), second["touched_count"].get<std::size_t>());
  CHECK(second["coverage"].get<double>() > 0.0);
  // Nothing new: an empty delta; the snapshot has them all.
  linked.link.on_record(record_at(3, Eigen::Vector3d(25.0, 12.5, 6.0), second["touched_count"].get<std::uint32_t>()));
  linked.publish();
  nlohmann::json third = state.frame(3, server);
  CHECK_EQUAL(0U, third["touched"].size());
  nlohmann::json whole = state.snapshot(3, server);
  CHECK(whole["touched"] == second["touched"]);
  STRCMP_EQUAL("snapshot", whole["type"].get<std::string>().c_str());
  DOUBLES_EQUAL(5.0, whole["limits"]["board_force_limit"].get<double>(), 0.0);
  // The probe is the device's position in the world.
  const Eigen::Vector3d probe = motion::device_to_world(config().frames, Eigen::Vector3d(250.0, 125.0, 60.0));
  DOUBLES_EQUAL(probe.x(), third["probe"][0].get<double>(), 1e-4);
  DOUBLES_EQUAL(probe.z(), third["probe"][2].get<double>(), 1e-4);
  // The part's mesh: every triangle, and the job it belongs to.
  const nlohmann::json part = nlohmann::json::parse(state.part_json());
  CHECK_EQUAL(prism.part.triangle_count(), part["triangles"].get<std::uint32_t>());
  CHECK_EQUAL(9U * prism.part.triangle_count(), part["vertices"].size());
  CHECK(part["job"] == whole["controller"]["job"]);
}

TEST(HmiLiveState, TheLargestForceSinceTheLastFrameIsKept) {
  Prism prism;
  Linked linked(prism.part, config());
  for (std::uint64_t cycle = 1; cycle <= 50; ++cycle) {
    control::JournalRecord r = record_at(cycle, Eigen::Vector3d(25.0, 12.5, 20.0), 0);
    r.force_n[2] = cycle == 17 ? 3.5F : 0.5F;
    linked.link.on_record(r);
  }
  linked.publish();
  DOUBLES_EQUAL(3.5, linked.state.frame(1, nlohmann::json::object())["force_peak"].get<double>(), 1e-6);
  linked.link.on_record(record_at(51, Eigen::Vector3d(25.0, 12.5, 20.0), 0));
  linked.publish();
  DOUBLES_EQUAL(0.0, linked.state.frame(2, nlohmann::json::object())["force_peak"].get<double>(), 1e-6);
}

TEST(HmiLiveState, StockChangesAreSentAsCellsAndASnapshotCarriesTheWholeGrid) {
  Prism prism;
  Linked linked(prism.part, config());
  LiveState& state = linked.state;
  const control::StockBlock block{Eigen::Vector3d(15.0, 3.0, 0.0), Eigen::Vector3d(35.0, 22.0, 7.0)};
  std::vector<float> cells(control::CommandedStock::cells_needed(block, 0.05));
  control::CommandedStock model(block, 0.05, prism.part.tool.spec, cells);
  CHECK(model.ready());
  linked.link.on_machine({0.1, {25.0, 12.5, 20.0}, false}, model);
  linked.publish();
  nlohmann::json first = state.frame(1, nlohmann::json::object());
  CHECK(first.contains("stock_grid"));  // the grid's shape is new: sent whole
  const int columns = first["stock_grid"]["columns"].get<int>();
  CHECK(columns > 10 && columns <= 100);
  model.cut(Eigen::Vector3d(16.0, 10.0, 5.0), Eigen::Vector3d(20.0, 10.0, 5.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(110));  // the stock is sampled at most 10 times a second
  linked.link.on_machine({0.2, {25.0, 12.5, 20.0}, false}, model);
  linked.publish();
  nlohmann::json second = state.frame(2, nlohmann::json::object());
  CHECK_FALSE(second.contains("stock_grid"));
  CHECK(second["stock"].size() > 0U);
  double lowest = 7.0;
  for (const auto& cell : second["stock"]) {
    CHECK(cell[1].get<double>() >= 5.0 - 0.01 && cell[1].get<double>() < 7.0);  // cut, never below the leg's tip
    lowest = std::min(lowest, cell[1].get<double>());
  }
  DOUBLES_EQUAL(5.0, lowest, 0.01);
  DOUBLES_EQUAL(0.2, second["lag_mm"].get<double>(), 1e-9);
  nlohmann::json third = state.frame(3, nlohmann::json::object());
  CHECK_EQUAL(0U, third["stock"].size());
  nlohmann::json whole = state.snapshot(3, nlohmann::json::object());
  CHECK_EQUAL(first["stock_grid"]["heights"].size(), whole["stock_grid"]["heights"].size());
}

TEST(HmiLiveState, AResetMayBeAskedOnlyInASafeStateWithTheHandleStillNearTheTool) {
  Prism prism;
  Linked linked(prism.part, config());
  linked.publish();
  STRCMP_CONTAINS("the job has ended", linked.state.reset_refusal().c_str());  // publish() marks it ended
  const display_link::ResetRule rule{config().still_time_s, config().reset_distance_mm};
  control::Telemetry t{};
  STRCMP_CONTAINS("not in a safe state", display_link::reset_refusal(false, t, rule).c_str());
  t.safe_reason = control::SafeReason::DeviceStale;
  t.device_still_s = 0.1;
  t.device_to_tool_mm = 1.0;
  STRCMP_CONTAINS("hold the handle still", display_link::reset_refusal(true, t, rule).c_str());
  t.device_still_s = 1.0;
  t.device_to_tool_mm = 12.0;
  STRCMP_CONTAINS("12.0 mm away", display_link::reset_refusal(true, t, rule).c_str());
  t.device_to_tool_mm = 2.0;
  STRCMP_EQUAL("", display_link::reset_refusal(true, t, rule).c_str());
}

TEST(HmiLiveState, TheEndOfTheJobIsShownWithItsLastState) {
  Prism prism;
  Linked linked(prism.part, config());
  linked.link.on_record(record_at(9, Eigen::Vector3d(25.0, 12.5, 20.0), 0));
  linked.link.end("the job ended after 9 cycles");
  linked.state.set_link(display_link::LinkState::Ended, "the controller ended");
  linked.state.update(&linked.view, 1);
  const nlohmann::json frame = linked.state.frame(1, nlohmann::json::object());
  CHECK(frame["controller"]["ended"].get<bool>());
  STRCMP_EQUAL("the job ended after 9 cycles", frame["controller"]["end"].get<std::string>().c_str());
  STRCMP_EQUAL("ended", frame["controller"]["state"].get<std::string>().c_str());
  CHECK_EQUAL(9U, frame["cycle"].get<std::uint64_t>());
}

TEST_GROUP(HmiTokenFile) {
  void teardown() override { unsetenv("CREDENTIALS_DIRECTORY"); }  // however a test ended
};

TEST(HmiTokenFile, OnlyAFileItsOwnerAloneMayReadGivesAToken) {
  Folder folder;
  const std::string path = (folder.dir / "token").string();
  std::ofstream(path) << "  s3cret-token \nsecond line\n";
  std::string token, error;
  chmod(path.c_str(), 0644);
  CHECK_FALSE(read_token_file(path, token, error));
  STRCMP_CONTAINS("mode 0644 lets others read it; chmod 600", error.c_str());
  chmod(path.c_str(), 0600);
  CHECK_TRUE_TEXT(read_token_file(path, token, error), error.c_str());
  STRCMP_EQUAL("s3cret-token", token.c_str());
  CHECK_FALSE(read_token_file((folder.dir / "missing").string(), token, error));
  STRCMP_CONTAINS("No such file", error.c_str());
  std::ofstream(path, std::ios::trunc) << "\n";
  CHECK_FALSE(read_token_file(path, token, error));
  STRCMP_CONTAINS("empty", error.c_str());
  const std::string link = (folder.dir / "link").string();
  CHECK(symlink(path.c_str(), link.c_str()) == 0);
  CHECK_FALSE(read_token_file(link, token, error));  // never followed: it could point anywhere
}

// systemd's LoadCredential=: root's file with an ACL for the unit's user, so its mode shows the mask
// (0440); taken as it is, but only straight from $CREDENTIALS_DIRECTORY.
TEST(HmiTokenFile, ASystemdCredentialIsTakenAsSystemdLeftIt) {
  Folder folder;
  const std::string path = (folder.dir / "token").string();
  std::ofstream(path) << "from-systemd\n";
  chmod(path.c_str(), 0440);
  std::string token, error;
  CHECK_FALSE(read_token_file(path, token, error));
  setenv("CREDENTIALS_DIRECTORY", folder.dir.c_str(), 1);
  CHECK_TRUE_TEXT(read_token_file(path, token, error), error.c_str());
  STRCMP_EQUAL("from-systemd", token.c_str());
  std::filesystem::create_directory(folder.dir / "deeper");
  const std::string deeper = (folder.dir / "deeper" / "token").string();
  std::ofstream(deeper) << "x\n";
  chmod(deeper.c_str(), 0440);
  CHECK_FALSE(read_token_file(deeper, token, error));  // only the folder's own files
  unsetenv("CREDENTIALS_DIRECTORY");
}

TEST_GROUP(DisplayApp) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(DisplayApp, ABrowsersRequestIsCheckedHereBeforeAnythingGoesToTheController) {
  DisplayAppOptions options;
  options.controller_socket = "/nonexistent/display.sock";
  options.quiet = true;
  DisplayApp app(options);
  nlohmann::json reply = nlohmann::json::parse(app.handle_message(1, true, "not json"));
  STRCMP_EQUAL("error", reply["type"].get<std::string>().c_str());
  reply = nlohmann::json::parse(app.handle_message(1, false, R"({"type":"reset"})"));
  STRCMP_EQUAL("refused", reply["type"].get<std::string>().c_str());
  STRCMP_CONTAINS("watch-only", reply["reason"].get<std::string>().c_str());
  reply = nlohmann::json::parse(app.handle_message(1, true, R"({"type":"set","name":"coupling","value":0.5})"));
  STRCMP_EQUAL("refused", reply["type"].get<std::string>().c_str());
  STRCMP_CONTAINS("no controller to take it", reply["reason"].get<std::string>().c_str());
  const DisplayCounters counters = app.counters();
  CHECK_EQUAL(1U, counters.malformed);
  CHECK_EQUAL(2U, counters.refused);
  CHECK_EQUAL(0U, counters.forwarded);
}
