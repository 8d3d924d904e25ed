// FakeCy545Clock over a real pty: virtual time that moves by each byte's wire time, waits out a busy
// chip that holds a question in its buffer, and jumps to a sleep's deadline, running the fake there.
#include <cstdint>

#include "sim/cy545/fake_cy545_clock.hpp"
#include "tests/sim/cy545/fake_cy545_bench.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::sim::cy545;
using namespace stencil::sim::cy545::test;

namespace {

constexpr double kBaud = 9600.0;
constexpr hal::MonotonicNs kByteNs = 1'041'666;  // ten bits at 9600 baud, truncated

}  // namespace

TEST_GROUP(FakeCy545Clock) {
  FakeCy545Bench bench;
  FakeCy545Clock clock{bench.fake, 0, kBaud};

  // Writes `bytes` and lets the clock (not the test) hand them to the fake.
  void write(std::string_view bytes) {
    CHECK_TRUE(bench.client.write_raw(bytes));
    CHECK_TRUE(bench.fake.wait_for_input(2000));
  }
};

TEST(FakeCy545Clock, EveryByteThatCrossesTheLineInEitherDirectionCostsItsWireTime) {
  write("\r? P\r");
  const hal::MonotonicNs now = clock.now_ns();
  STRCMP_EQUAL("P=0\r", bench.client.read_until_cr(2000).c_str());
  LONGS_EQUAL(5 + 4, bench.fake.pty_counters().bytes_read + bench.fake.pty_counters().bytes_written);
  LONGS_EQUAL(9 * kByteNs, now);
  LONGS_EQUAL(now, clock.now_ns());  // nothing crossed since: no time passed
}

TEST(FakeCy545Clock, TheChipTakesItsCommandTimeForEveryCommand) {
  write("\rN 5\r");
  static_cast<void>(clock.now_ns());
  CHECK_TRUE(bench.fake.chip().busy());
  clock.sleep_until_ns(clock.now_ns() + Cy545Chip::kCommandTimeNs);
  CHECK_FALSE(bench.fake.chip().busy());
}

TEST(FakeCy545Clock, ADriverWaitingOnABusyChipWithAByteInItsBufferWaitsUntilTheChipIsFree) {
  write("\rD 50\r");
  static_cast<void>(clock.now_ns());
  CHECK_TRUE(bench.fake.chip().busy());
  write("?");
  const hal::MonotonicNs now = clock.now_ns();
  // The delay began with its CR, the sixth byte (five byte times in); the wait ends within 1 ms of it.
  CHECK_TRUE(now >= 50 * kMs + 5 * kByteNs);
  CHECK_TRUE(now < 51 * kMs + 7 * kByteNs);
  CHECK_FALSE(bench.fake.chip().busy());
}

TEST(FakeCy545Clock, SleepingJumpsToTheDeadlineAndRunsTheFakeThereButNeverBack) {
  write("\rR 100\rN 3\rG\r");
  static_cast<void>(clock.now_ns());
  const hal::MonotonicNs start = bench.fake.now_ns();
  clock.sleep_until_ns(start + 35 * kMs);  // past the move's 30 ms
  CHECK_FALSE(bench.fake.chip().busy());
  LONGS_EQUAL(3, bench.fake.chip().counters().steps_issued);
  const hal::MonotonicNs after = clock.now_ns();
  clock.sleep_until_ns(0);
  LONGS_EQUAL(after, clock.now_ns());
}
