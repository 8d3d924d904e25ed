// The display's options for both controllers (firmware/programs/display_option): --hmi with or
// without an endpoint, its token file needed beyond loopback, --hmi-token-file and --hmi-assets only
// with --hmi, --hmi and --display-socket not together. The Display itself (a socket and a process of
// its own) is end to end: e2e sim_killing_the_display_changes_nothing, hmi_browser and hmi_operator.
#include <string>
#include <vector>

#include "firmware/programs/display_option.hpp"
#include "tests/support/command_line.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

struct Checked {
  CLI::App app;
  app::DisplayOptions options;
  std::string error;
  bool ok = false;
  explicit Checked(const std::vector<std::string>& words) {
    app::add_display_options(app, options);
    test::parse_words(app, words);
    ok = app::check_display_options(options, error);
  }
};

}  // namespace

TEST_GROUP(DisplayOption){};

TEST(DisplayOption, NoDisplayIsAsked) {
  const Checked c({});
  CHECK_TRUE(c.ok);
  CHECK_FALSE(c.options.hmi());
  CHECK_FALSE(c.options.requested());
}

TEST(DisplayOption, HmiAloneIsTheLoopbackDefault) {
  const Checked c({"--hmi"});
  CHECK_TRUE(c.ok);
  CHECK_TRUE(c.options.hmi());
  CHECK_TRUE(c.options.requested());
  STRCMP_EQUAL("", c.options.endpoint.c_str());
}

TEST(DisplayOption, ASocketAloneIsRequestedButNotHmi) {
  const Checked c({"--display-socket", "/tmp/display.sock"});
  CHECK_TRUE(c.ok);
  CHECK_FALSE(c.options.hmi());
  CHECK_TRUE(c.options.requested());
}

TEST(DisplayOption, BeyondLoopbackNeedsAToken) {
  const Checked open({"--hmi", "0.0.0.0:8080"});
  CHECK_FALSE(open.ok);
  STRCMP_EQUAL("--hmi 0.0.0.0: listening beyond loopback needs --hmi-token-file FILE", open.error.c_str());
  CHECK_TRUE(Checked({"--hmi", "0.0.0.0:8080", "--hmi-token-file", "token"}).ok);
  CHECK_TRUE(Checked({"--hmi", "127.0.0.1:9000"}).ok);
}

TEST(DisplayOption, ABadEndpointIsNamedAsHmis) {
  const Checked c({"--hmi", "127.0.0.1:99999"});
  CHECK_FALSE(c.ok);
  CHECK_EQUAL(0U, c.error.find("--hmi "));
}

TEST(DisplayOption, TheDisplaysOwnOptionsGoWithHmi) {
  STRCMP_EQUAL("--hmi-token-file and --hmi-assets go with --hmi", Checked({"--hmi-token-file", "t"}).error.c_str());
  STRCMP_EQUAL("--hmi-token-file and --hmi-assets go with --hmi", Checked({"--hmi-assets", "/srv/page"}).error.c_str());
}

TEST(DisplayOption, HmiAndASocketAreOneOrTheOther) {
  STRCMP_CONTAINS("--hmi and --display-socket", Checked({"--hmi", "--display-socket", "/tmp/s"}).error.c_str());
}
