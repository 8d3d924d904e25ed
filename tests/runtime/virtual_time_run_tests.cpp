// The virtual-time run: the cycle and the machine side take turns in the order the records depend
// on, the hooks are called at their points, and a safe state ends the run once the mill is stopped
// and the device drives no force.
#include <initializer_list>
#include <string>

#include "firmware/runtime/job.hpp"
#include "firmware/runtime/virtual_time_run.hpp"
#include "tests/runtime/job_bench.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

// The diary of machine updates with `cycles[i]` cycles after the i-th, and one more update.
std::string updates_with_cycles_between(std::initializer_list<int> cycles) {
  std::string diary;
  for (const int n : cycles) {
    diary += 'M';
    for (int i = 0; i < n; ++i) {
      diary += "Cc";
    }
  }
  diary += 'M';
  return diary;
}

}  // namespace

TEST_GROUP(VirtualTimeRun){};

// An update every 33.3 ms: the first at the first cycle's deadline, then 34 cycles, then 33 (and
// 34 again every third update), each between its hooks.
TEST(VirtualTimeRun, TheMachineUpdatesFirstThenRunsEveryCycleDueBeforeItsNextUpdate) {
  test::JobBench bench;
  runtime::Job job(bench.parts(), runtime::Timing::Virtual);
  STRCMP_EQUAL("", job.error().c_str());
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DiaryHook diary;
  diary.last_cycle = 67;
  runtime::JobHooks* const hooks[] = {&diary};
  const runtime::RunOutcome outcome = runtime::run_on_virtual_time(job, hooks, {});
  STRCMP_EQUAL(updates_with_cycles_between({34, 33}).c_str(), diary.diary.c_str());
  LONGS_EQUAL(67, job.controller().statistics().cycles);
  DOUBLES_EQUAL(0.067, outcome.run_s, 1e-12);
  LONGS_EQUAL(67, diary.telemetry_frames);
  LONGS_EQUAL(3, diary.request_calls);  // with the display's: every 20th cycle
}

TEST(VirtualTimeRun, AHookIsAskedEachSecondWhetherTheJobIsDoneAndItsYesEndsTheRun) {
  test::JobBench bench;
  runtime::Job job(bench.parts(), runtime::Timing::Virtual);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DiaryHook diary;
  diary.done_at_s = 2.0;
  runtime::JobHooks* const hooks[] = {&diary};
  const runtime::RunOutcome outcome = runtime::run_on_virtual_time(job, hooks, {});
  LONGS_EQUAL(3, diary.seconds_asked.size());
  DOUBLES_EQUAL(0.999, diary.seconds_asked[0], 1e-12);
  DOUBLES_EQUAL(2.999, diary.seconds_asked[2], 1e-12);
  LONGS_EQUAL(3000, job.controller().statistics().cycles);
  CHECK(outcome.safe_state_s < 0.0);
  LONGS_EQUAL(1, bench.link.stops());  // stopped on the way out
}

// Cycles that start 1.5 periods late (an injected stalled host): the fourth overrun in a row is the
// safe state. The watchdog enters it in finish(), after the cycle's handoff went: no update at once,
// the mill is stopped at the next one.
TEST(VirtualTimeRun, AHooksLatenessMakesTheCyclesLateAndTheOverrunWatchdogSeesIt) {
  test::JobBench bench;
  runtime::Job job(bench.parts(true), runtime::Timing::Virtual);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DiaryHook diary;
  diary.late_ns = 1'500'000;
  runtime::JobHooks* const hooks[] = {&diary};
  const runtime::RunOutcome outcome = runtime::run_on_virtual_time(job, hooks, {});
  STRCMP_EQUAL("overrun_storm", control::safe_reason_name(job.controller().safe_reason()));
  DOUBLES_EQUAL(0.003, outcome.safe_state_s, 1e-12);
  DOUBLES_EQUAL(0.034, outcome.machine_stopped_s, 1e-12);
  // No one says what the device drives here: the run ends a tenth of a second after the safe state.
  CHECK(outcome.force_zero_s < 0.0);
  DOUBLES_EQUAL(0.134, outcome.run_s, 1e-12);  // the first update over 0.1 s after the safe state
}

TEST(VirtualTimeRun, ASafeStateEndsTheRunAtTheUpdateAfterTheMillStoppedAndTheForceWentToZero) {
  test::JobBench bench;
  runtime::Job job(bench.parts(), runtime::Timing::Virtual);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DeviceFaultAt fault(bench.device, 101);
  test::DiaryHook diary;
  runtime::JobHooks* const hooks[] = {&fault, &diary};
  runtime::VirtualTimeRun options;
  options.device_force_off = [&bench] { return !bench.device.last_command().enable; };
  const runtime::RunOutcome outcome = runtime::run_on_virtual_time(job, hooks, options);
  STRCMP_EQUAL("device_fault", control::safe_reason_name(job.controller().safe_reason()));
  DOUBLES_EQUAL(0.100, outcome.safe_state_s, 1e-12);
  DOUBLES_EQUAL(0.100, outcome.force_zero_s, 1e-12);
  DOUBLES_EQUAL(0.101, outcome.machine_stopped_s, 1e-12);  // an update at once, after the safe cycle
  DOUBLES_EQUAL(0.101, outcome.run_s, 1e-12);
  LONGS_EQUAL(1, bench.link.stops());
  LONGS_EQUAL(101, job.controller().statistics().cycles);
}
