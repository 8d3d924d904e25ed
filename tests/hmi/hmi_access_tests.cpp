// The display's access rules (hmi_access.hpp): the endpoint it listens on, a token needed beyond
// loopback and only its holder controlling, the page's own origin only, and the token file only its
// owner may read (or systemd's credential as systemd left it). Against real files in /tmp.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "firmware/services/hmi/hmi_access.hpp"
#include "tests/support/temp_folder.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::hmi;
using stencil::testing::TempFolder;

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

TEST_GROUP(HmiTokenFile) {
  void teardown() override { unsetenv("CREDENTIALS_DIRECTORY"); }  // however a test ended
};

TEST(HmiTokenFile, OnlyAFileItsOwnerAloneMayReadGivesAToken) {
  TempFolder folder("hmi-tests");
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
  TempFolder folder("hmi-tests");
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
