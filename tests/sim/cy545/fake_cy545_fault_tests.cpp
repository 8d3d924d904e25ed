// The fake CY545's fault hooks: stop replying, garbled replies, unsolicited garbage, a wrong position,
// an unplugged port, a reset that needs the baud rate locked again.
#include <cerrno>
#include <string>

#include "tests/sim/cy545/fake_cy545_bench.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using namespace stencil::sim::cy545;
using namespace stencil::sim::cy545::test;

TEST_GROUP(FakeCy545Faults) {
  FakeCy545Bench bench;
  void setup() override { CHECK_TRUE(bench.send("\r")); }
};

TEST(FakeCy545Faults, StopReplyingStillExecutesButSendsNothing) {
  bench.fake.set_replies_suppressed(true);
  CHECK_TRUE(bench.send("N 12\r? N\r"));
  STRCMP_EQUAL("", bench.client.read_for(100).c_str());
  UNSIGNED_LONGS_EQUAL(12, bench.fake.chip().step_count());
  LONGS_EQUAL(5, bench.fake.pty_counters().replies_suppressed);   // "N=12\r"
  bench.fake.set_replies_suppressed(false);
  STRCMP_EQUAL("N=12\r", bench.query("? N\r").c_str());
}

TEST(FakeCy545Faults, GarbledRepliesHaveTheirTopBitFlipped) {
  bench.fake.set_replies_garbled(true);
  CHECK_TRUE(bench.send("? N\r"));
  const std::string garbled = bench.client.read_for(200);
  LONGS_EQUAL(4, static_cast<long>(garbled.size()));
  const std::string expected = "N=0\r";
  for (std::size_t i = 0; i < expected.size(); ++i) {
    LONGS_EQUAL(static_cast<unsigned char>(expected[i]) ^ 0x80, static_cast<unsigned char>(garbled[i]));
  }
}

TEST(FakeCy545Faults, UnsolicitedGarbageReachesTheDriver) {
  bench.fake.send_unsolicited("#?X=\x01\r");
  STRCMP_EQUAL("#?X=\x01\r", bench.client.read_until_cr(2000).c_str());
  LONGS_EQUAL(6, bench.fake.pty_counters().bytes_written);
}

TEST(FakeCy545Faults, WrongPositionIsReportedButTheRegisterAndMillAreUntouched) {
  bench.fake.set_reported_position_offset(5);
  STRCMP_EQUAL("P=5\r", bench.query("? P\r").c_str());
  STRCMP_EQUAL("A=5\r", bench.query("? A\r").c_str());
  UNSIGNED_LONGS_EQUAL(0, bench.fake.chip().position_register());
  bench.fake.set_reported_position_offset(-1);
  STRCMP_EQUAL("P=16777215\r", bench.query("? P\r").c_str());
  STRCMP_EQUAL("N=0\r", bench.query("? N\r").c_str());   // only positions are wrong
}

TEST(FakeCy545Faults, ClosingThePtyHangsUpTheDriversSide) {
  bench.fake.close_pty();
  CHECK_FALSE(bench.fake.pty_open());
  LONGS_EQUAL(-1, bench.fake.master_fd());
  // The driver's side: reading sees end of file or EIO, writing fails.
  static_cast<void>(bench.client.read_for(200));
  CHECK_TRUE(bench.client.hung_up());
  CHECK_FALSE(bench.client.write_raw("? P\r"));
  LONGS_EQUAL(EIO, bench.client.last_errno());
  // The fake keeps its clock and state; writes to nowhere are counted.
  bench.fake.advance(5 * kMs);
  LONGS_EQUAL(5 * kMs, bench.fake.now_ns());
  bench.fake.send_unsolicited("xy");
  LONGS_EQUAL(2, bench.fake.pty_counters().write_failures);
}

TEST(FakeCy545Faults, ResetPinNeedsTheBaudRateLockedAgain) {
  CHECK_TRUE(bench.send("N 8\r"));
  bench.fake.chip().power_on_reset();
  CHECK_FALSE(bench.fake.chip().baud_locked());
  CHECK_TRUE(bench.send("? N\r"));
  STRCMP_EQUAL("", bench.client.read_for(100).c_str());
  STRCMP_EQUAL("N=0\r", bench.query("? N\r").c_str());   // the CR above locked it
}
