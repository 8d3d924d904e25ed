// The fake CY545 serviced in real time by its runner thread: replies and move timing on the wall clock.
#include <chrono>
#include <cstdint>
#include <thread>

#include "board/sim/sim_facts.hpp"
#include "sim/cy545/fake_cy545_runner.hpp"
#include "tests/sim/cy545/pty_test_client.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil::sim;
using namespace stencil::sim::cy545;
using namespace stencil::sim::cy545::test;

TEST_GROUP(FakeCy545Runner) {
  SimulatedMill mill{stencil::board::sim::kMillConfig};
};

TEST(FakeCy545Runner, AnswersQueriesWithoutTheTestSteppingIt) {
  FakeCy545 fake{mill, stencil::board::sim::kMmc4sWiring, stencil::hal::posix_clock::monotonic_now_ns()};
  FakeCy545Runner runner{fake};
  PtyTestClient client{fake.slave_path()};
  CHECK_TRUE(client.write_raw("\rN 10\r? N\r"));
  STRCMP_EQUAL("N=10\r", client.read_until_cr(2000).c_str());
}

TEST(FakeCy545Runner, AMoveTakesAtLeastItsStepsOverRateOfWallTime) {
  FakeCy545 fake{mill, stencil::board::sim::kMmc4sWiring, stencil::hal::posix_clock::monotonic_now_ns()};
  FakeCy545Runner runner{fake};
  PtyTestClient client{fake.slave_path()};
  const std::int64_t x0 = mill.axis_position_steps(Axis::x);
  CHECK_TRUE(client.write_raw("\rB 43H\rB 7\r/B 7\rR 1000\rN 100\rG\r"));  // X's line latched on
  const auto sent = std::chrono::steady_clock::now();
  // Wait (bounded) for the chip to take the G and then to finish it.
  const auto deadline = sent + std::chrono::seconds(3);
  bool started = false;
  bool finished = false;
  while (!finished && std::chrono::steady_clock::now() < deadline) {
    runner.with_fake([&](FakeCy545& f) {
      if (f.chip().counters().commands_executed >= 6) started = true;
      finished = started && !f.chip().busy();
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const auto elapsed = std::chrono::steady_clock::now() - sent;
  CHECK_TRUE(finished);
  // The steps are timed from when the chip received the G, which is after it was written.
  CHECK_TRUE(elapsed >= std::chrono::milliseconds(100));
  runner.with_fake([&](FakeCy545& f) {
    LONGS_EQUAL(0, f.chip().counters().malformed_lines);
    LONGS_EQUAL(0, f.chip().counters().bytes_before_baud_lock);
    LONGS_EQUAL(6, f.chip().counters().commands_executed);
    LONGS_EQUAL(3, f.chip().user_bit_latches());  // "B 43H": bit 0 the driver enable, bit 1 the data
    LONGS_EQUAL(100, f.chip().counters().steps_issued);
    LONGS_EQUAL(0, f.board().steps_to_no_channel());
    CHECK_TRUE(mill.drivers_enabled());
    LONGS_EQUAL(x0 + 100, mill.axis_position_steps(Axis::x));
  });
}
