// Commissioning the simulated rig (board/sim/simulated_commissioning): the CY545 driver homes the
// simulated mill over the fake chip's pty on virtual time, and a simulated machinist reads the dial
// indicator from the mill's truth; the compiled-in rig on its own mill passes with every jog as
// commanded, and a mill whose x axis really runs the other way is found out. The program's report of
// it: e2e sim_commissioning_finds_a_wrong_sign_and_wrong_steps.
#include <cmath>
#include <string>
#include <vector>

#include "board/sim/sim_job.hpp"
#include "board/sim/simulated_commissioning.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

struct Commissioning {
  test::LoadedPart loaded{test::default_part(), 1};
  SimJob job;
  std::vector<std::string> said;
  Commissioning() {
    job.part = &loaded.part;
    job.stock = default_stock(loaded.part);
  }
  board::sherline_suzuki::CommissioningResult run() {
    // Short jogs keep it quick: the mill steps at its own rate even on virtual time.
    return commission_simulated_rig(job, board::sherline_suzuki::CommissioningSettings{1.0, 0.02}, nullptr,
                                    [this](const std::string& line) { said.push_back(line); });
  }
};

}  // namespace

TEST_GROUP(SimulatedCommissioning){};

TEST(SimulatedCommissioning, TheRigOnItsOwnMillPassesWithEveryJogAsCommanded) {
  Commissioning c;
  const board::sherline_suzuki::CommissioningResult result = c.run();
  CHECK_TRUE(result.homed);
  CHECK_TEXT(result.passed, result.findings.empty() ? "" : result.findings[0].c_str());
  for (const double moved : result.moved_mm) {
    DOUBLES_EQUAL(1.0, std::abs(moved), 0.02);
  }
  // The machinist's answers are said, to the indicator's thousandth.
  bool answered = false;
  for (const std::string& line : c.said) {
    answered = answered || line.find("(the simulated machinist)") != std::string::npos;
  }
  CHECK_TRUE(answered);
}

TEST(SimulatedCommissioning, AnAxisThatRunsTheOtherWayIsFound) {
  Commissioning c;
  c.job.rig.mill_truth.mmc4s.step_direction[0] = -c.job.rig.mill_truth.mmc4s.step_direction[0];
  const board::sherline_suzuki::CommissioningResult result = c.run();
  CHECK_FALSE(result.passed);
  CHECK_FALSE(result.findings.empty());
}
