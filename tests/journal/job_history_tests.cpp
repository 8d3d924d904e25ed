// read_job_history (job_history.hpp): one pass over a job's journal gives what a resume and the report
// need: its runs, cycles, time and faults per run, how each run ended, the legs its targets sent the
// tool along (from home after each homing, one axis at a time), the virtual tips that rebuild the
// touched set (each only when it moved), the largest force and offset (recorded, or worked out for an
// old journal); and refuses a journal of other tables or without its start first. Against journals
// the real writer (or OldJournal) makes.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/services/journal/job_history.hpp"
#include "firmware/services/journal/journal_format.hpp"
#include "firmware/services/journal/journal_reader.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "tests/support/journal_fixtures.hpp"
#include "tests/support/old_journal.hpp"

#include <CppUTest/TestHarness.h>

using stencil::control::JournalRecord;
using stencil::control::MachineCommandRecord;
using stencil::control::SafeReason;
using stencil::testing::OldJournal;
using namespace stencil::journal;
using namespace stencil::testing;

namespace {

// Device mm are twice world mm, the origins together; home is 50 mm up.
const stencil::motion::MachineFrames kFrames{2.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, 50.0), {1, 1, 1},
                                             1000.0};

// A cycle at (1, 2, 3) until cycle 5, where the tool moved to (1, 2, 4) and touched its first triangle.
JournalRecord moving_cycle(std::uint64_t cycle, SafeReason reason = SafeReason::None) {
  JournalRecord r = record_of(cycle, reason);
  r.virtual_tip_mm[0] = 1.0;
  r.virtual_tip_mm[1] = 2.0;
  r.virtual_tip_mm[2] = cycle < 5 ? 3.0 : 4.0;
  r.touched_triangles = cycle < 5 ? 0 : 1;
  r.max_force_n = cycle == 3 ? 6.5 : 1.0;
  r.max_offset_mm = cycle == 6 ? 0.75 : 0.25;
  return r;
}

MachineCommandRecord target(std::uint64_t update, Eigen::Vector3d tip_mm, std::uint8_t first, std::uint8_t second,
                            std::uint8_t third) {
  return {update, 0, {0, 0, 0}, {first, second, third}, {tip_mm.x(), tip_mm.y(), tip_mm.z()}};
}

struct Rebuilt {
  std::vector<Eigen::Vector3d> tips;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> legs;
  HistoryRebuild rebuild() {
    HistoryRebuild r;
    r.virtual_tip = [this](const Eigen::Vector3d& tip) { tips.push_back(tip); };
    r.machined_leg = [this](const Eigen::Vector3d& from, const Eigen::Vector3d& to) { legs.emplace_back(from, to); };
    return r;
  }
};

bool same(const Eigen::Vector3d& want, const Eigen::Vector3d& got) { return want == got; }

// Run 1 (killed after cycle 9, in a pose-jump safe state from cycle 8): homed, two targets. Run 2
// (resumed, ended in order after 5 cycles): homed again, one target. Returns where run 2 starts.
std::size_t write_two_runs(const std::string& path) {
  {
    JournalWriter writer;
    CHECK_TRUE(writer.open(path, start_of()));
    CHECK_TRUE(writer.append_homed(1));
    // X, then Y, then Z from home: three legs.
    CHECK_TRUE(writer.append_machine_command(target(0, {10.0, 20.0, 30.0}, 0, 1, 2)));
    // Already there: no leg.
    CHECK_TRUE(writer.append_machine_command(target(1, {10.0, 20.0, 30.0}, 2, 3, 0)));
    CHECK_TRUE(writer.write_machine_commands());
    for (std::uint64_t c = 0; c < 10; ++c) {
      CHECK_TRUE(writer.append(moving_cycle(c, c >= 8 ? SafeReason::PoseJump : SafeReason::None)));
    }
    CHECK_TRUE(writer.close());  // no End record: as if killed
  }
  const JournalReadResult first = read_journal_file(path, {});
  CHECK_TEXT(first.ok, first.error.c_str());
  JournalWriter writer;
  JournalResume resume;
  resume.segment = 1;
  resume.script_s = 10.0;
  resume.approach_s = 0.002;
  CHECK_TRUE(writer.open_to_resume(path, first.good_bytes, resume));
  CHECK_TRUE(writer.append_homed(2));
  // Only X names an axis: one leg, from home.
  CHECK_TRUE(writer.append_machine_command(target(0, {5.0, 99.0, 99.0}, 0, 3, 3)));
  CHECK_TRUE(writer.write_machine_commands());
  for (std::uint64_t c = 0; c < 5; ++c) {
    JournalRecord r = moving_cycle(5 + c);  // still at (1, 2, 4)
    r.cycle = c;
    r.time_ns = static_cast<std::int64_t>(c) * 1'000'000;
    CHECK_TRUE(writer.append(r));
  }
  CHECK_TRUE(writer.append_end(5, SafeReason::None));
  CHECK_TRUE(writer.close());
  return first.good_bytes;
}

}  // namespace

TEST_GROUP(JobHistory){};

TEST(JobHistory, AJobOfTwoRunsIsCountedRunByRunWithHowEachEnded) {
  TempJournal file;
  const std::size_t second_run = write_two_runs(file.path);
  JobHistory history;
  std::string error;
  CHECK_TEXT(read_job_history(file.path, 0xdeadbeef, 92, kFrames, {}, history, error), error.c_str());
  STRCMP_EQUAL("journal_tests", history.start.program.c_str());
  LONGS_EQUAL(2, history.segments);
  LONGS_EQUAL(15, history.cycles);
  LONGS_EQUAL(2, history.homings);
  LONGS_EQUAL(3, history.machine_commands);
  LONGS_EQUAL(1, history.faults.size());
  LONGS_EQUAL(0, history.faults[0].segment);
  LONGS_EQUAL(8, history.faults[0].cycle);
  CHECK(history.faults[0].reason == SafeReason::PoseJump);
  LONGS_EQUAL(2, history.endings.size());
  CHECK_FALSE(history.endings[0].recorded);
  LONGS_EQUAL(10, history.endings[0].cycles);
  CHECK_TRUE(history.endings[1].recorded);
  CHECK(history.endings[1].reason == SafeReason::None);
  LONGS_EQUAL(5, history.endings[1].cycles);
  // Each run's span plus its last cycle's millisecond: 9 + 1 and 4 + 1.
  DOUBLES_EQUAL(0.015, history.recorded_s, 1e-9);
  // The script carries on where the resume said, once the way back (2 ms) was made.
  DOUBLES_EQUAL(10.0 + 0.005 - 0.002, history.script_s, 1e-9);
  LONGS_EQUAL(1, history.run_starts.size());
  LONGS_EQUAL(second_run, history.run_starts[0]);
  LONGS_EQUAL(file.bytes().size(), history.good_bytes);
  CHECK_TRUE(history.tail.empty());
  LONGS_EQUAL(1, history.touched_recorded);
  DOUBLES_EQUAL(6.5, history.max_force_n, 0.0);
  DOUBLES_EQUAL(0.75, history.max_offset_mm, 0.0);
  CHECK_TRUE(history.has_cycle);
  CHECK(same({1.0, 2.0, 4.0}, history.last_virtual_tip_mm));
  CHECK(same({5.0, 99.0, 99.0}, history.last_commanded_tip_mm));
}

// The touched set is rebuilt from each tip that moved (not each recorded), and the stock from each
// single-axis leg in the order sent, starting at home after every homing.
TEST(JobHistory, TheRebuildSeesEachTipThatMovedAndEachLegFromHomeAfterAHoming) {
  TempJournal file;
  static_cast<void>(write_two_runs(file.path));
  Rebuilt rebuilt;
  JobHistory history;
  std::string error;
  CHECK_TEXT(read_job_history(file.path, 0xdeadbeef, 92, kFrames, rebuilt.rebuild(), history, error), error.c_str());
  LONGS_EQUAL(2, rebuilt.tips.size());
  CHECK(same({1.0, 2.0, 3.0}, rebuilt.tips[0]));
  CHECK(same({1.0, 2.0, 4.0}, rebuilt.tips[1]));
  LONGS_EQUAL(4, history.machined_legs);
  LONGS_EQUAL(4, rebuilt.legs.size());
  CHECK(same({0.0, 0.0, 50.0}, rebuilt.legs[0].first));
  CHECK(same({10.0, 0.0, 50.0}, rebuilt.legs[0].second));
  CHECK(same({10.0, 20.0, 50.0}, rebuilt.legs[1].second));
  CHECK(same({10.0, 20.0, 30.0}, rebuilt.legs[2].second));
  CHECK(same({0.0, 0.0, 50.0}, rebuilt.legs[3].first));  // homed again
  CHECK(same({5.0, 0.0, 50.0}, rebuilt.legs[3].second));
}

// What the file held before this run carried it on: the first run only.
TEST(JobHistory, ALimitReadsOnlyTheJobAsItWasBeforeThatPoint) {
  TempJournal file;
  const std::size_t second_run = write_two_runs(file.path);
  JobHistory history;
  std::string error;
  CHECK_TEXT(read_job_history(file.path, 0xdeadbeef, 92, kFrames, {}, history, error, second_run), error.c_str());
  LONGS_EQUAL(1, history.segments);
  LONGS_EQUAL(10, history.cycles);
  LONGS_EQUAL(1, history.endings.size());
  LONGS_EQUAL(second_run, history.good_bytes);
  CHECK(same({10.0, 20.0, 30.0}, history.last_commanded_tip_mm));
}

// Versions 2 to 4 kept no maxima: the force is the recorded force's size, the offset the device's
// point in the world against the tool, outside the safe state only.
TEST(JobHistory, AnOldJournalsMaximaAreWorkedOutFromItsCycles) {
  TempJournal file;
  OldJournal version2(2);
  JournalRecord calm = record_of(0);
  calm.force_n[0] = 3.0F;
  calm.force_n[1] = 4.0F;
  calm.force_n[2] = 0.0F;
  calm.device_mm[0] = 2.0;  // world (1, 2, 3)
  calm.device_mm[1] = 4.0;
  calm.device_mm[2] = 6.0;
  calm.virtual_tip_mm[0] = 1.0;
  calm.virtual_tip_mm[1] = 2.0;
  calm.virtual_tip_mm[2] = 5.0;  // 2 mm off
  version2.cycle(calm);
  JournalRecord safe = calm;  // far off, but in the safe state: not an offset the operator felt
  safe.cycle = 1;
  safe.device_mm[2] = 600.0;
  safe.safe_reason = SafeReason::PoseJump;
  version2.cycle(safe);
  version2.write(file.path);
  JobHistory history;
  std::string error;
  CHECK_TEXT(read_job_history(file.path, 0xdeadbeef, 92, kFrames, {}, history, error), error.c_str());
  DOUBLES_EQUAL(5.0, history.max_force_n, 1e-6);
  DOUBLES_EQUAL(2.0, history.max_offset_mm, 1e-12);
  LONGS_EQUAL(2, history.cycles);
  LONGS_EQUAL(1, history.faults.size());
  LONGS_EQUAL(1, history.endings.size());
}

TEST(JobHistory, AJournalOfOtherTablesOrWithoutItsStartFirstIsRefusedNamingTheFile) {
  TempJournal file;
  write_job(file.path, 2);
  JobHistory history;
  std::string error;
  CHECK_FALSE(read_job_history(file.path, 0x12345678, 92, kFrames, {}, history, error));
  STRCMP_EQUAL((file.path + ": recorded with the tables of CRC-32 deadbeef and 92 triangles; these are 12345678 with 92 triangles").c_str(),
               error.c_str());
  CHECK_FALSE(read_job_history(file.path, 0xdeadbeef, 91, kFrames, {}, history, error));
  STRCMP_CONTAINS("these are deadbeef with 91 triangles", error.c_str());

  // A start record twice: two old journals' records one after the other.
  OldJournal first(3);
  first.cycle(record_of(0));
  const OldJournal second(3);
  std::vector<std::uint8_t> twice = first.bytes();
  twice.insert(twice.end(), second.bytes().begin() + static_cast<long>(kFileHeaderBytes), second.bytes().end());
  std::FILE* out = std::fopen(file.path.c_str(), "wb");
  CHECK(out != nullptr);
  CHECK_EQUAL(twice.size(), std::fwrite(twice.data(), 1, twice.size(), out));
  std::fclose(out);
  CHECK_FALSE(read_job_history(file.path, 0xdeadbeef, 92, kFrames, {}, history, error));
  STRCMP_EQUAL((file.path + ": a record before the start record, or a second start record").c_str(), error.c_str());

  // The file header alone: no start record.
  std::vector<std::uint8_t> header(first.bytes().begin(), first.bytes().begin() + static_cast<long>(kFileHeaderBytes));
  out = std::fopen(file.path.c_str(), "wb");
  CHECK(out != nullptr);
  CHECK_EQUAL(header.size(), std::fwrite(header.data(), 1, header.size(), out));
  std::fclose(out);
  CHECK_FALSE(read_job_history(file.path, 0xdeadbeef, 92, kFrames, {}, history, error));
  STRCMP_EQUAL((file.path + ": no start record (expected one first, naming the tables)").c_str(), error.c_str());

  CHECK_FALSE(read_job_history("/nonexistent/job.journal", 0xdeadbeef, 92, kFrames, {}, history, error));
  STRCMP_EQUAL("/nonexistent/job.journal: cannot be read", error.c_str());
}
