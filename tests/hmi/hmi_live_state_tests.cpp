// The display's live state (hmi_live_state.hpp), built from a controller's feed through a real
// DisplayLink: the touched set mirrored and sent as deltas then whole, the stock as cells and a
// grid, the largest force since the last frame, what it says with no controller and at the job's
// end, and reset and pause refused when there is nothing to reset or pause.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/tables/table_loader.hpp"
#include "firmware/services/display_link/display_link.hpp"
#include "firmware/services/hmi/hmi_live_state.hpp"
#include "tests/support/sample_tables.hpp"
#include "tests/support/temp_folder.hpp"

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
  testing::TempFolder folder{"hmi-tests"};
  display_link::DisplayLink link;
  display_link::FeedView view;
  LiveState state;
  Linked(const tables::PartTables& part, const control::ControllerConfig& c)
      : link(part, c, {folder.file("display.sock"), "stencil-test", false}) {
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

TEST_GROUP(HmiLiveState) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(HmiLiveState, JsonGoesToThePageCompactWithBadUtf8ReplacedInsteadOfAThrow) {
  // A part's file name is whatever bytes the file system holds: "\xff" is no UTF-8.
  const nlohmann::json value = {{"part", std::string("hex\xff.stl")}, {"n", 2}};
  STRCMP_EQUAL("{\"n\":2,\"part\":\"hex\xef\xbf\xbd.stl\"}", json_text(value).c_str());
}

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

TEST(HmiLiveState, ResetAndPauseAreRefusedWithoutAControllerAndOnceTheJobHasEnded) {
  LiveState alone;
  STRCMP_EQUAL("no controller", alone.reset_refusal().c_str());
  STRCMP_EQUAL("no controller", alone.pause_refusal(display_link::RequestKind::Pause).c_str());
  Prism prism;
  Linked linked(prism.part, config());
  linked.publish();
  STRCMP_CONTAINS("the job has ended", linked.state.reset_refusal().c_str());  // publish() marks it ended
  STRCMP_CONTAINS("the job has ended", linked.state.pause_refusal(display_link::RequestKind::Resume).c_str());
  // The frame says the same to the page.
  const nlohmann::json frame = linked.state.frame(1, nlohmann::json::object());
  CHECK_FALSE(frame["safe"]["reset_allowed"].get<bool>());
  STRCMP_EQUAL("the job has ended", frame["safe"]["reset_refusal"].get<std::string>().c_str());
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
