// stencil-sim's command line (firmware/programs/sim_options): the options parsed as the program
// parses them, then how they combine (check_sim_options: the clock, the real-time options, --inject
// read into its fault, --replay and --commission implying the virtual clock and no journal, the
// outputs that exclude each other), and the configuration files read over the defaults
// (apply_sim_config). The program's exit on each refusal: e2e sim_refuses_a_bad_inject and others.
#include <string>
#include <vector>

#include "firmware/programs/sim_options.hpp"
#include "tests/support/command_line.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using stencil::app::SimOptions;

namespace {

// The words parsed and checked; the error ("" when accepted).
struct Checked {
  CLI::App app;
  SimOptions options;
  std::string error;
  bool ok = false;
  explicit Checked(const std::vector<std::string>& words) {
    app::add_sim_options(app, options);
    test::parse_words(app, words);
    ok = app::check_sim_options(app, options, error);
  }
};

}  // namespace

TEST_GROUP(SimOptions){};

TEST(SimOptions, FastAloneRunsOnTheVirtualClockWithAJournal) {
  const Checked c({"--fast"});
  CHECK_TRUE(c.ok);
  CHECK_TRUE(c.options.fast);
  CHECK_FALSE(c.options.no_journal);
  CHECK_FALSE(c.options.real_time());
  STRCMP_EQUAL("raster", c.options.pattern_name.c_str());
}

TEST(SimOptions, TheClockMustBeChosenOnce) {
  STRCMP_EQUAL("pass --fast (virtual time) or --speed N (N x real time)", Checked({}).error.c_str());
  STRCMP_EQUAL("--fast and --speed: choose one", Checked({"--fast", "--speed", "2"}).error.c_str());
  const Checked real_time({"--speed", "1"});
  CHECK_TRUE(real_time.ok);
  CHECK_TRUE(real_time.options.real_time());
}

TEST(SimOptions, RealTimeOptionsGoWithSpeed1Only) {
  const char* expected = "--priority, --cpu and --require-rt are for the real-time threads of --speed 1 only";
  STRCMP_EQUAL(expected, Checked({"--fast", "--priority", "50"}).error.c_str());
  STRCMP_EQUAL(expected, Checked({"--speed", "3", "--require-rt"}).error.c_str());
  const Checked ok({"--speed", "1", "--priority", "50", "--cpu", "1"});
  CHECK_TRUE(ok.ok);
  CHECK_EQUAL(50, ok.options.priority);
  CHECK_EQUAL(1, ok.options.cpu);
}

TEST(SimOptions, InjectIsReadIntoItsFaultAndTime) {
  const Checked c({"--fast", "--inject", "pose-nan@2.5"});
  CHECK_TRUE(c.ok);
  CHECK(c.options.fault.kind == board::sim::FaultKind::PoseNan);
  DOUBLES_EQUAL(2.5, c.options.fault.at_s, 0.0);
}

TEST(SimOptions, ABadInjectIsRefusedListingTheKinds) {
  for (const char* bad : {"pose-melt@1", "pose-nan", "pose-nan@", "pose-nan@-1", "pose-nan@nan", "pose-nan@1x"}) {
    const Checked c({"--fast", "--inject", bad});
    CHECK_FALSE(c.ok);
    STRCMP_CONTAINS("expected KIND@SECONDS, KIND one of device-frozen, pose-nan,", c.error.c_str());
    STRCMP_CONTAINS((std::string("--inject ") + bad + ":").c_str(), c.error.c_str());
  }
}

TEST(SimOptions, CanBadFramesNeedsCanAndNoFaultOnTheWallClock) {
  STRCMP_CONTAINS("(--haptic-transport can)", Checked({"--fast", "--inject", "can-bad-frames@1"}).error.c_str());
  CHECK_TRUE(Checked({"--fast", "--inject", "can-bad-frames@1", "--haptic-transport", "can"}).ok);
  STRCMP_EQUAL("--inject: faults are injected on the virtual clock (--fast or --speed N other than 1)",
               Checked({"--speed", "1", "--inject", "pose-nan@1"}).error.c_str());
  CHECK_TRUE(Checked({"--speed", "4", "--inject", "pose-nan@1"}).ok);
}

TEST(SimOptions, AReplayRunsOnTheVirtualClockWithoutAJournal) {
  const Checked alone({"--replay", "job.journal"});
  CHECK_TRUE(alone.ok);
  CHECK_TRUE(alone.options.fast);
  CHECK_TRUE(alone.options.no_journal);
  const Checked paced({"--replay", "job.journal", "--speed", "2"});
  CHECK_TRUE(paced.ok);
  CHECK_FALSE(paced.options.fast);  // paced virtual time
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--replay", "j", "--journal", "k"}, {"--replay", "j", "--resume", "k"},
        {"--replay", "j", "--speed", "1"}, {"--replay", "j", "--inject", "pose-nan@1"},
        {"--replay", "j", "--display-socket", "/tmp/s"}}) {
    STRCMP_CONTAINS("--replay runs the recorded job on the virtual clock by itself", Checked(bad).error.c_str());
  }
}

TEST(SimOptions, CommissioningRunsOnTheVirtualClockByItself) {
  const Checked c({"--commission"});
  CHECK_TRUE(c.ok);
  CHECK_TRUE(c.options.fast);
  CHECK_TRUE(c.options.no_journal);
  STRCMP_CONTAINS("--commission runs on the virtual clock by itself", Checked({"--commission", "--speed", "2"}).error.c_str());
  STRCMP_CONTAINS("--commission runs on the virtual clock by itself",
                  Checked({"--commission", "--resume", "j"}).error.c_str());
}

TEST(SimOptions, JournalOptionsThatExcludeEachOtherAreRefused) {
  STRCMP_EQUAL("--out-dir: a --resume or a --replay writes in its journal's folder",
               Checked({"--fast", "--out-dir", "/tmp/jobs", "--resume", "j"}).error.c_str());
  STRCMP_EQUAL("--resume carries on in the journal it resumes: no --journal or --no-journal with it",
               Checked({"--fast", "--resume", "j", "--no-journal"}).error.c_str());
  STRCMP_EQUAL("--journal and --no-journal: choose one", Checked({"--fast", "--journal", "j", "--no-journal"}).error.c_str());
}

TEST(SimOptions, TheDeviceProcessNeedsPioAndNoInject) {
  const char* expected = "--device-process: the device runs in its own process only with --haptic-transport pio and no --inject";
  STRCMP_EQUAL(expected, Checked({"--fast", "--device-process", "d.log"}).error.c_str());
  STRCMP_EQUAL(expected, Checked({"--fast", "--device-process", "d.log", "--haptic-transport", "pio", "--inject",
                                  "pose-nan@1"})
                             .error.c_str());
  CHECK_TRUE(Checked({"--fast", "--device-process", "d.log", "--haptic-transport", "pio"}).ok);
}

// Issue 29: the hand and the wall's feel; by default today's placed hand and no feel at all.
TEST(SimOptions, TheHandAndTheWallsFeelDefaultToTodaysAndAreChecked) {
  const Checked plain({"--fast"});
  STRCMP_EQUAL("placed", plain.options.hand.c_str());
  DOUBLES_EQUAL(0.0, plain.options.damping_n_s_per_m, 0.0);
  DOUBLES_EQUAL(0.0, plain.options.friction, 0.0);
  STRCMP_EQUAL("cap", plain.options.speed_limiting.c_str());
  const Checked felt({"--fast", "--hand", "stiff", "--damping", "40", "--friction", "0.5", "--speed-limiting", "penalty"});
  CHECK_TRUE(felt.ok);
  STRCMP_EQUAL("stiff", felt.options.hand.c_str());
  DOUBLES_EQUAL(40.0, felt.options.damping_n_s_per_m, 0.0);
  DOUBLES_EQUAL(0.5, felt.options.friction, 0.0);
  STRCMP_EQUAL("penalty", felt.options.speed_limiting.c_str());
  CHECK_THROWS(CLI::ValidationError, Checked({"--fast", "--hand", "firm"}));
  CHECK_THROWS(CLI::ValidationError, Checked({"--fast", "--friction", "1.5"}));
  CHECK_THROWS(CLI::ValidationError, Checked({"--fast", "--damping", "-1"}));
  CHECK_THROWS(CLI::ValidationError, Checked({"--fast", "--speed-limiting", "brake"}));
  STRCMP_EQUAL("--device-process: the device's own process moves the placed hand only (no --hand medium)",
               Checked({"--fast", "--device-process", "d.log", "--haptic-transport", "pio", "--hand", "medium"}).error.c_str());
}

TEST(SimOptions, CliRefusesAnUnknownPatternOrTransport) {
  CHECK_THROWS(CLI::ValidationError, Checked({"--fast", "--pattern", "zigzag"}));
  CHECK_THROWS(CLI::ValidationError, Checked({"--fast", "--haptic-transport", "usb"}));
}

TEST(SimOptions, TheConfigurationFileGivesTheRigAndItsThreadsUnlessTheCommandLineDoes) {
  Checked c({"--speed", "1", "--config", STENCIL_RIG_TOML, "--cpu", "3"});
  CHECK_TRUE(c.ok);
  std::string error;
  CHECK_TRUE(app::apply_sim_config(c.app, c.options, error));
  CHECK(c.options.config_crc32 != 0U);
  CHECK(c.options.rig.facts == c.options.rig.mill_truth);  // the mill as configured
  CHECK_EQUAL(3, c.options.cpu);                             // the command line's
  CHECK_EQUAL(0U, c.options.mill_truth_crc32);
}

TEST(SimOptions, WithoutAFileTheCompiledInRigIsKept) {
  Checked c({"--fast"});
  std::string error;
  CHECK_TRUE(app::apply_sim_config(c.app, c.options, error));
  CHECK(c.options.rig.facts == board::sherline_suzuki::kRig);
  CHECK_EQUAL(0U, c.options.config_crc32);
  CHECK_EQUAL(80, c.options.priority);
}

TEST(SimOptions, ABadMillTruthFileIsNamedAsThat) {
  Checked c({"--fast", "--mill-truth", "/nonexistent/truth.toml"});
  std::string error;
  CHECK_FALSE(app::apply_sim_config(c.app, c.options, error));
  CHECK_EQUAL(0U, error.find("--mill-truth: "));
}

// G-code: a program as the operator is one motion among the others; cut directly it has no controller,
// so nothing that needs one goes with it; the export is written from the journal.
TEST(SimOptions, GcodeOptionsThatCannotGoTogetherAreRefusedNamingThem) {
  const Checked both({"--fast", "--operator", "a.csv", "--gcode-operator", "a.ngc"});
  CHECK_FALSE(both.ok);
  STRCMP_CONTAINS("--operator and --gcode-operator: choose one", both.error.c_str());
  for (const std::vector<std::string>& words : std::vector<std::vector<std::string>>{
           {"--gcode-direct", "a.ngc", "--gcode-operator", "b.ngc"},
           {"--gcode-direct", "a.ngc", "--gcode", "b.ngc"},
           {"--gcode-direct", "a.ngc", "--journal", "j.journal"},
           {"--gcode-direct", "a.ngc", "--inject", "pose-nan@1"}}) {
    const Checked c(words);
    CHECK_FALSE(c.ok);
    STRCMP_CONTAINS("--gcode-direct cuts the program with no controller", c.error.c_str());
  }
  const Checked no_journal({"--fast", "--no-journal", "--gcode", "cut.ngc"});
  CHECK_FALSE(no_journal.ok);
  STRCMP_CONTAINS("--gcode writes the program from the job's journal", no_journal.error.c_str());
}

TEST(SimOptions, GcodeDirectNeedsNoClockAndKeepsNoJournal) {
  const Checked c({"--gcode-direct", "a.ngc"});
  CHECK_TRUE(c.ok);
  CHECK_TRUE(c.options.fast);
  CHECK_TRUE(c.options.no_journal);
  const Checked guard({"--fast", "--gcode-operator", "a.ngc", "--gcode", "cut.ngc"});
  CHECK_TRUE(guard.ok);
  CHECK_FALSE(guard.options.no_journal);
}

// --linuxcnc-samples is the ground truth of a LinuxCNC mill: refused, named, with a CY545 rig (the
// compiled-in one here). The LinuxCNC configuration's own refusals (no --speed 1, no samples, a
// simulated mill's options) run end to end in e2e.linuxcnc_*.
TEST(SimOptions, LinuxcncSamplesWithoutALinuxcncConfigurationAreRefused) {
  Checked c({"--speed", "1", "--linuxcnc-samples", "/tmp/samples.txt"});
  CHECK_TRUE(c.ok);
  std::string error;
  CHECK_FALSE(app::apply_sim_config(c.app, c.options, error));
  STRCMP_CONTAINS("--linuxcnc-samples: only with a --config whose machine.controller is \"linuxcnc\"", error.c_str());
  CHECK_FALSE(c.options.linuxcnc.has_value());
}
