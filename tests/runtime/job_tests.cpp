// A job's assembly and start: a resumed job's history rebuilt from its journal before the machine
// homes (what was touched, the model of what was cut, each leg passed on to the board), a journal
// that cannot be read refused before anything moves, and a spindle that starts only once confirmed.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>

#include <unistd.h>

#include "firmware/runtime/job.hpp"
#include "firmware/runtime/virtual_time_run.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/runtime/job_bench.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;

namespace {

// Draws the handle 1 mm (world) towards -x over the first second, at the virtual tool's speed.
class HandDrawnBack final : public runtime::JobHooks {
 public:
  HandDrawnBack(test::FakeHapticDevice& device, const Eigen::Vector3d& home_world_mm)
      : device_(device), home_device_mm_(10.0 * home_world_mm) {}
  bool before_cycle(const runtime::CycleTime& time) override {
    const double moved_mm = 10.0 * std::min(1.0, 0.9 * time.t_s);
    device_.hold_at(home_device_mm_.x() - moved_mm, home_device_mm_.y(), home_device_mm_.z());
    return true;
  }

 private:
  test::FakeHapticDevice& device_;
  Eigen::Vector3d home_device_mm_;
};

}  // namespace

TEST_GROUP(Job){};

TEST(Job, AJournalToResumeFromThatCannotBeReadIsRefusedBeforeAnythingMoves) {
  test::JobBench bench;
  runtime::JobParts parts = bench.parts();
  parts.resume_from = "/nonexistent/job.journal";
  runtime::Job job(parts, runtime::Timing::Virtual);
  STRCMP_CONTAINS("--resume: ", job.error().c_str());
  CHECK_FALSE(bench.link.status().homed);
}

TEST(Job, TheSpindleStartsOnlyOnceTheOperatorConfirmsIt) {
  test::JobBench bench;
  runtime::Job job(bench.parts(), runtime::Timing::RealTime);
  runtime::MachineStart start;
  start.after_homing_within_ns = 2 * test::kUpdateNs;
  bool asked_while_homed = false;
  start.confirm_spindle = [&] {
    asked_while_homed = bench.link.status().homed && !bench.link.status().spindle_on;
    return false;
  };
  const runtime::StartFailure failure = job.start_machine(start);
  CHECK(failure == runtime::StartFailure::SpindleNotConfirmed);
  CHECK_TRUE(asked_while_homed);
  STRCMP_EQUAL("the spindle was not confirmed: nothing was cut", job.describe(failure).c_str());
  LONGS_EQUAL(1, bench.link.stops());  // drivers off: nothing runs unattended
  CHECK_FALSE(bench.link.status().spindle_on);
}

// A first run draws the tool 1 mm along the top of the stock (cutting 0.5 mm of it) with a journal;
// the job carried on from that journal starts from the touched set and the model of the stock the
// first run left, and hands each leg the mill cut to the board (the simulation's mill cuts its own
// stock along them).
TEST(Job, AResumedJobRebuildsWhatWasTouchedAndCutFromItsJournal) {
  char name[] = "/tmp/runtime_job_tests_XXXXXX";
  const int fd = mkstemp(name);
  CHECK(fd >= 0);
  close(fd);
  double first_removed_mm3 = 0.0;
  {
    test::JobBench bench;
    journal::JournalWriter writer;
    journal::JournalStart start;
    start.tables_crc32 = bench.part.header.crc32;
    start.triangle_count = bench.part.header.triangle_count;
    start.program = "runtime_job_tests";
    CHECK_TRUE(writer.open(name, start));
    runtime::JobParts parts = bench.parts();
    parts.stock.high_mm.z() = 20.5;
    parts.journal = &writer;
    runtime::Job job(parts, runtime::Timing::Virtual);
    CHECK(job.start_machine({}) == runtime::StartFailure::None);
    HandDrawnBack hand(bench.device, bench.home_world_mm);
    test::DiaryHook diary;
    diary.done_at_s = 2.0;
    runtime::JobHooks* const hooks[] = {&hand, &diary};
    static_cast<void>(runtime::run_on_virtual_time(job, hooks, {}));
    first_removed_mm3 = job.model().removed_volume_mm3();
    CHECK_TRUE(writer.close());
  }
  CHECK(first_removed_mm3 > 0.0);
  test::JobBench bench;
  runtime::JobParts parts = bench.parts();
  parts.stock.high_mm.z() = 20.5;
  parts.resume_from = name;
  parts.resume_bytes = std::numeric_limits<std::size_t>::max();  // all of it
  int legs = 0;
  parts.recorded_leg = [&legs](const Eigen::Vector3d&, const Eigen::Vector3d&) { ++legs; };
  runtime::Job job(parts, runtime::Timing::Virtual);
  STRCMP_EQUAL("", job.error().c_str());
  LONGS_EQUAL(1, job.earlier().segments);
  CHECK(job.earlier().machine_commands > 0);
  LONGS_EQUAL(job.earlier().machined_legs, legs);
  LONGS_EQUAL(job.earlier().touched_recorded, job.touched_rebuilt());
  DOUBLES_EQUAL(first_removed_mm3, job.model().removed_volume_mm3(), 1e-9);
  CHECK_FALSE(bench.link.status().homed);  // rebuilt before the machine homes
  std::remove(name);
}
