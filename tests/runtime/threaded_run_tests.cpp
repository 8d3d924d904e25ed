// The run on threads, on the wall clock with the real-time runner (unprivileged where the host
// gives no privileges): how it ends (the run's own stop through the cycle, a safe state), what a
// fault's safe state does under each ending, and the mill stopped on the way out even when the
// runner refused to run the cycle.
#include <atomic>
#include <functional>
#include <string>

#include "firmware/runtime/job.hpp"
#include "firmware/runtime/realtime_thread.hpp"
#include "firmware/runtime/threaded_run.hpp"
#include "hal/posix_clock/monotonic_clock.hpp"
#include "tests/runtime/job_bench.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

runtime::PeriodicRunner unprivileged_runner() {
  return app::realtime_runner({80, -1, false}, [](const std::string&) {});
}

// The bench on the wall clock: the machine thread paces on CLOCK_MONOTONIC, as the runner does.
struct WallClockBench {
  test::JobBench bench;
  hal::posix_clock::MonotonicClock clock;
  runtime::JobParts parts() {
    runtime::JobParts parts = bench.parts(false);
    parts.machine_clock = &clock;
    parts.controller.stale_periods = 100;  // not a real-time host: a stalled thread is not a lost device
    return parts;
  }
};

}  // namespace

TEST_GROUP(ThreadedRun){};

TEST(ThreadedRun, ItsTimeUpTheRunEndsThroughTheCyclesOwnStopAndTheMillIsStopped) {
  WallClockBench wall;
  runtime::Job job(wall.parts(), runtime::Timing::RealTime);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DiaryHook diary;
  runtime::JobHooks* const hooks[] = {&diary};
  runtime::ThreadedRun options;
  options.safe_state_ends = runtime::SafeStateEnds::AfterStop;
  options.stop_after_s = 0.5;
  options.settle_ns = 3 * test::kUpdateNs;
  const runtime::RunOutcome outcome = runtime::run_on_threads(job, unprivileged_runner(), hooks, options);
  CHECK_TRUE(outcome.ran);
  STRCMP_EQUAL("stopped", control::safe_reason_name(job.controller().safe_reason()));
  STRCMP_EQUAL("none", control::safe_reason_name(outcome.first_fault));
  CHECK(outcome.run_s >= 0.5);
  CHECK(diary.telemetry_frames > 0 && diary.request_calls > 0);
  LONGS_EQUAL(1, wall.bench.link.stops());
}

TEST(ThreadedRun, AFaultsSafeStateKeepsTheCycleRunningUntilTheRunsStopWhenOnlyAStopEndsIt) {
  WallClockBench wall;
  runtime::Job job(wall.parts(), runtime::Timing::RealTime);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DeviceFaultAt fault(wall.bench.device, 100);
  runtime::JobHooks* const hooks[] = {&fault};
  runtime::ThreadedRun options;
  options.safe_state_ends = runtime::SafeStateEnds::AfterStop;
  options.stop_after_s = 0.5;
  const runtime::RunOutcome outcome = runtime::run_on_threads(job, unprivileged_runner(), hooks, options);
  STRCMP_EQUAL("device_fault", control::safe_reason_name(outcome.first_fault));
  STRCMP_EQUAL("device_fault", control::safe_reason_name(job.controller().safe_reason()));  // latched
  CHECK(outcome.run_s >= 0.5);
  CHECK(job.controller().statistics().cycles > 300);
}

TEST(ThreadedRun, AnySafeStateEndsTheRunWhenSoAsked) {
  WallClockBench wall;
  runtime::Job job(wall.parts(), runtime::Timing::RealTime);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  test::DeviceFaultAt fault(wall.bench.device, 100);
  runtime::JobHooks* const hooks[] = {&fault};
  const runtime::RunOutcome outcome = runtime::run_on_threads(job, unprivileged_runner(), hooks, {});
  STRCMP_EQUAL("device_fault", control::safe_reason_name(job.controller().safe_reason()));
  LONGS_EQUAL(100, job.controller().statistics().cycles);
  LONGS_EQUAL(1, wall.bench.link.stops());
  CHECK(outcome.run_s < 1.0);
}

TEST(ThreadedRun, WhenTheRunnerRefusesItSaysWhyAndTheMillIsStoppedAllTheSame) {
  WallClockBench wall;
  runtime::Job job(wall.parts(), runtime::Timing::RealTime);
  CHECK(job.start_machine({}) == runtime::StartFailure::None);
  const runtime::PeriodicRunner refusing = [](hal::MonotonicNs, const std::atomic<bool>&,
                                              const std::function<bool(hal::MonotonicNs, hal::MonotonicNs)>&,
                                              std::string& refused) {
    refused = "no SCHED_FIFO here";
    return false;
  };
  const runtime::RunOutcome outcome = runtime::run_on_threads(job, refusing, {}, {});
  CHECK_FALSE(outcome.ran);
  STRCMP_EQUAL("no SCHED_FIFO here", outcome.error.c_str());
  LONGS_EQUAL(0, outcome.start_ns);
  LONGS_EQUAL(1, wall.bench.link.stops());
}
