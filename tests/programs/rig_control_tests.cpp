// `stencil-rig status|stop|reset|pause|resume|start` (firmware/programs/rig_control): each a
// subcommand with --socket (the service's socket by default) and --timeout, and no controller at the
// socket found out within the timeout (exit 3). The commands against a running controller: e2e
// sim_control_commands_reach_a_running_controller.
#include <chrono>
#include <string>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "firmware/programs/rig_control.hpp"
#include "tests/support/command_line.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct Parsed {
  CLI::App app;
  app::ControlOptions options;
  explicit Parsed(const std::vector<std::string>& words) {
    app::add_control_commands(app, options);
    test::parse_words(app, words);
  }
};

}  // namespace

TEST_GROUP(RigControl) {
  int saved_stderr = -1;
  // The refusal's line goes to stderr: kept out of the test's output.
  void setup() override {
    saved_stderr = dup(STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDERR_FILENO);
    close(null);
  }
  void teardown() override {
    dup2(saved_stderr, STDERR_FILENO);
    close(saved_stderr);
  }
};

TEST(RigControl, EachVerbIsASubcommandOnTheServicesSocketByDefault) {
  for (const char* verb : {"status", "stop", "reset", "pause", "resume", "start"}) {
    const Parsed c({verb});
    CHECK(c.options.chosen != nullptr);
    STRCMP_EQUAL(verb, c.options.chosen->get_name().c_str());
    STRCMP_EQUAL(app::kServiceSocket, c.options.socket_path.c_str());
    DOUBLES_EQUAL(5.0, c.options.timeout_s, 0.0);
  }
}

TEST(RigControl, NoVerbIsAJob) {
  const Parsed c({});
  CHECK(c.options.chosen == nullptr);
}

TEST(RigControl, TheSocketAndTimeoutAreTheCommandsOwn) {
  const Parsed c({"pause", "--socket", "/tmp/control.sock", "--timeout", "0.5"});
  STRCMP_EQUAL("pause", c.options.chosen->get_name().c_str());
  STRCMP_EQUAL("/tmp/control.sock", c.options.socket_path.c_str());
  DOUBLES_EQUAL(0.5, c.options.timeout_s, 0.0);
  CHECK_THROWS(CLI::ValidationError, Parsed({"status", "--timeout", "0"}));
  CHECK_THROWS(CLI::ValidationError, Parsed({"status", "--timeout", "61"}));
}

TEST(RigControl, NoControllerAtTheSocketIsExit3WithinTheTimeout) {
  app::ControlOptions options;
  options.socket_path = "/tmp/rig_control_tests_" + std::to_string(getpid()) + ".sock";  // nothing there
  options.timeout_s = 0.2;
  const auto start = std::chrono::steady_clock::now();
  CHECK_EQUAL(3, app::run_control("status", options));
  CHECK_EQUAL(3, app::run_control("stop", options));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(2));
}
