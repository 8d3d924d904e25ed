// stencil-display's handling of a browser's message (display_app.hpp), without a socket: it is
// parsed and checked here (malformed, watch-only, no controller) before anything goes to the
// controller, each outcome counted, and the reply names the request it refuses.
#include <string>

#include <nlohmann/json.hpp>

#include "firmware/services/hmi/display_app.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil::hmi;

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

// A display opened with a token tells the watcher how to control; the refusal names the request
// (its parameter and value for a set) so the page can show which of its requests it was.
TEST(DisplayApp, ARefusalNamesTheRequestAndAWatchOnlyPageIsToldHowToControl) {
  DisplayAppOptions options;
  options.controller_socket = "/nonexistent/display.sock";
  options.web.token = "s3cret-token";
  options.quiet = true;
  DisplayApp app(options);
  nlohmann::json reply = nlohmann::json::parse(app.handle_message(7, false, R"({"type":"set","name":"force_limit","value":2.5})"));
  STRCMP_EQUAL("refused", reply["type"].get<std::string>().c_str());
  STRCMP_EQUAL("set", reply["request"].get<std::string>().c_str());
  STRCMP_EQUAL("force_limit", reply["name"].get<std::string>().c_str());
  CHECK(reply.contains("value"));
  DOUBLES_EQUAL(2.5, reply["value"].get<double>(), 0.0);
  STRCMP_EQUAL("this display is watch-only: open it with ?token=... to change anything",
               reply["reason"].get<std::string>().c_str());
  reply = nlohmann::json::parse(app.handle_message(7, true, R"({"type":"stop"})"));
  STRCMP_EQUAL("stop", reply["request"].get<std::string>().c_str());
  CHECK_FALSE(reply.contains("name"));
  STRCMP_CONTAINS("no controller to take it", reply["reason"].get<std::string>().c_str());
  reply = nlohmann::json::parse(app.handle_message(7, true, R"({"type":"launch"})"));
  STRCMP_EQUAL("error", reply["type"].get<std::string>().c_str());
  STRCMP_CONTAINS("unknown \"type\" 'launch'", reply["error"].get<std::string>().c_str());
  CHECK_FALSE(reply.contains("request"));
  const DisplayCounters counters = app.counters();
  CHECK_EQUAL(1U, counters.malformed);
  CHECK_EQUAL(2U, counters.refused);
  CHECK_EQUAL(0U, counters.forwarded);
  CHECK_EQUAL(0U, counters.accepted);
}
