// Commissioning (board/sherline_suzuki/commissioning.hpp) with the rig's CY545 driver against the
// fake CY545 and the simulated mill on virtual time, the machinist scripted: a mill whose truth differs
// from the configuration (a motor wired backwards, steps per mm 1 % off, more backlash) is found out
// before any cut, and the right configuration passes.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "board/sherline_suzuki/commissioning.hpp"
#include "board/sim/sim_facts.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/cy545/serial_port.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_clock.hpp"
#include "sim/mill/simulated_mill.hpp"

#include <CppUTest/TestHarness.h>

namespace {

using namespace stencil;
namespace rig = board::sherline_suzuki;

// The rig as configured, and the mill as it is.
struct Bench {
  rig::RigFacts configured;
  sim::SimulatedMill mill;
  sim::cy545::FakeCy545 fake;
  sim::cy545::FakeCy545Clock clock;
  hal::cy545::SerialPort port;
  hal::cy545::Cy545Link link;

  Bench(const rig::RigFacts& configured_facts, const rig::RigFacts& truth)
      : configured(configured_facts),
        mill(board::sim::mill_config(truth)),
        fake(mill, truth.mmc4s, 0),
        clock(fake, 0, configured_facts.serial_baud),
        link(port, clock, board::sim::link_config(false, configured_facts)) {
    char error[256] = {};
    CHECK_TEXT(port.open(fake.slave_path().c_str(), configured_facts.serial_baud, error), error);
    fake.board().set_channel_latching(sim::cy545::ChannelLatching::Address);
    fake.chip().set_command_time_ns(0);
  }
};

// Reads the true position (world mm, as the rig's geometry maps the mill's steps, to 0.001 mm), unless told to
// answer otherwise; stops answering after `answers` readings when that is not negative.
class ScriptedMachinist final : public rig::CommissioningOperator {
 public:
  ScriptedMachinist(const Bench& bench, const rig::RigFacts& truth) : bench_(bench), truth_(truth) {}

  void say(const std::string& line) override { said.push_back(line); }
  bool reading(int axis, const std::string& question, const std::function<void()>& idle, double& mm) override {
    idle();
    questions.push_back(question);
    if (answers == 0) return false;
    --answers;
    const auto steps = bench_.mill.axis_position_steps(static_cast<sim::Axis>(axis));
    const double world = flip * truth_.machine_sign[static_cast<std::size_t>(axis)] * static_cast<double>(steps) /
                         truth_.steps_per_mm;
    mm = std::round(world * 1000.0) / 1000.0;  // a dial indicator's 0.001 mm
    return true;
  }

  std::vector<std::string> said, questions;
  int answers = -1;
  double flip = 1.0;  // -1: the indicator is read the other way round

 private:
  const Bench& bench_;
  rig::RigFacts truth_;
};

bool any_contains(const std::vector<std::string>& lines, const std::string& part) {
  for (const std::string& line : lines) {
    if (line.find(part) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST_GROUP(Commissioning){};

TEST(Commissioning, a_configuration_that_agrees_with_the_mill_passes_and_measures_its_backlash) {
  Bench bench(rig::kRig, rig::kRig);
  ScriptedMachinist machinist(bench, rig::kRig);
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_TRUE(result.homed);
  CHECK_TEXT(result.passed, result.findings.empty() ? "" : result.findings[0].c_str());
  CHECK(result.backlash_mm == rig::kRig.backlash_mm);
  STRCMP_EQUAL("backlash_mm = [0.125, 0.05, 0.125]", result.backlash_line.c_str());
  DOUBLES_EQUAL(-5.0, result.moved_mm[0], 1e-9);
  CHECK_EQUAL(9U, machinist.questions.size());
  // Back at home (approached from its + side: the nut a backlash out), spindle and drivers off.
  CHECK(bench.link.status().commanded_steps == (std::array<std::int32_t, 3>{0, 0, 0}));
  CHECK_FALSE(bench.mill.spindle_on());
  CHECK_FALSE(bench.mill.drivers_enabled());
}

TEST(Commissioning, a_step_direction_the_mill_does_not_have_is_stopped_by_homing_before_any_jog) {
  rig::RigFacts truth = rig::kRig;
  truth.mmc4s.step_direction[0] = -1;  // X's direction line wired the other way round
  Bench bench(rig::kRig, truth);
  ScriptedMachinist machinist(bench, truth);
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_FALSE(result.homed);
  CHECK_FALSE(result.passed);
  CHECK(any_contains(result.findings,
                     "homing axis X: no home switch within 40960 steps of travel moving -: check its step direction"));
  CHECK(machinist.questions.empty());
  CHECK_FALSE(bench.mill.drivers_enabled());
}

// The sign that maps the mill's axis onto the part (which way the table moves) is no matter to
// homing: the indicator finds it.
TEST(Commissioning, an_axis_sign_the_mill_does_not_have_is_found_by_the_indicator) {
  rig::RigFacts truth = rig::kRig;
  truth.machine_sign[1] = 1;
  Bench bench(rig::kRig, truth);
  ScriptedMachinist machinist(bench, truth);
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_TRUE(result.homed);
  CHECK_FALSE(result.passed);
  CHECK(any_contains(result.findings, "axis Y: moved +5.000 mm along the part's axis for -5.000 commanded: it runs the "
                                      "other way (or not at all); check machine.axis_sign"));
  CHECK_FALSE(any_contains(result.findings, "axis X"));
}

// A configured step direction of -1 is driven as such: the driver sends '-' where the mill's line is reversed.
TEST(Commissioning, a_reversed_direction_line_configured_as_such_passes) {
  rig::RigFacts reversed = rig::kRig;
  reversed.mmc4s.step_direction = {-1, 1, -1};
  Bench bench(reversed, reversed);
  ScriptedMachinist machinist(bench, reversed);
  const rig::CommissioningResult result = rig::commission(reversed, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_TEXT(result.passed, result.findings.empty() ? "" : result.findings[0].c_str());
}

TEST(Commissioning, an_axis_read_going_the_other_way_is_named) {
  Bench bench(rig::kRig, rig::kRig);
  ScriptedMachinist machinist(bench, rig::kRig);
  machinist.flip = -1.0;
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_FALSE(result.passed);
  CHECK(any_contains(result.findings, "axis X: moved +5.000 mm along the part's axis for -5.000 commanded: it runs the "
                                      "other way (or not at all); check machine.axis_sign"));
}

TEST(Commissioning, steps_per_mm_one_percent_off_are_measured) {
  rig::RigFacts truth = rig::kRig;
  truth.steps_per_mm = 646.4;
  truth.backlash_mm = {80 / 646.4, 32 / 646.4, 80 / 646.4};
  Bench bench(rig::kRig, truth);
  ScriptedMachinist machinist(bench, truth);
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_FALSE(result.passed);
  CHECK(any_contains(result.findings, "axis Y: moved 4.950 mm for 5.000 mm commanded (-1.00 %): machine.steps_per_mm "
                                      "would be 646.46; the file says 640"));
}

TEST(Commissioning, a_backlash_within_the_indicators_tolerance_passes_with_its_line) {
  rig::RigFacts truth = rig::kRig;
  truth.backlash_mm[0] = 0.125 + 5.0 / 640.0;  // 5 steps, 7.8 um: under the 0.02 mm tolerance
  Bench bench(rig::kRig, truth);
  ScriptedMachinist machinist(bench, truth);
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_TEXT(result.passed, result.findings.empty() ? "" : result.findings[0].c_str());
  STRCMP_EQUAL("backlash_mm = [0.1328125, 0.05, 0.125]", result.backlash_line.c_str());
}

TEST(Commissioning, more_backlash_than_the_file_says_is_proposed_as_the_line_to_write) {
  rig::RigFacts truth = rig::kRig;
  truth.backlash_mm[1] = 0.1;  // 64 steps
  Bench bench(rig::kRig, truth);
  ScriptedMachinist machinist(bench, truth);
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_FALSE(result.passed);
  STRCMP_EQUAL("backlash_mm = [0.125, 0.1, 0.125]", result.backlash_line.c_str());
  CHECK(any_contains(result.findings, "put `backlash_mm = [0.125, 0.1, 0.125]` in [machine] (the file says [0.125, 0.05, 0.125])"));
}

TEST(Commissioning, no_reading_ends_it_with_the_mill_stopped) {
  Bench bench(rig::kRig, rig::kRig);
  ScriptedMachinist machinist(bench, rig::kRig);
  machinist.answers = 1;  // the X axis's reading at home, then nothing
  const rig::CommissioningResult result = rig::commission(rig::kRig, {}, bench.link, bench.clock, machinist, nullptr);
  CHECK_FALSE(result.passed);
  CHECK(any_contains(result.findings, "no reading for axis X: commissioning ended"));
  CHECK(result.backlash_line.empty());
  CHECK_FALSE(bench.mill.drivers_enabled());
}
