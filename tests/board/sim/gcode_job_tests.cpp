// A G-code program in the simulation: the lines the stencil refuses (only those that go into the
// part, a retract out of it not), the operator's script that follows it at its feeds under the
// mill's speed, and the program cut with no stencil.
#include <vector>

#include "board/sim/gcode_job.hpp"
#include "board/sim/sim_job.hpp"
#include "tests/support/loaded_part.hpp"

#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;
using stencil::sim::GcodeMove;
using stencil::sim::GcodeMoveKind;
using stencil::sim::GcodeProgram;

namespace {

// The hex prism: top face z = 6, centred at (25, 12.5), circumradius 8.
const Eigen::Vector3d kStart(25.0, 12.5, 10.0);

GcodeMove feed(int line, double x, double y, double z, double feed_mm_per_min = 60.0) {
  return {line, GcodeMoveKind::Feed, {x, y, z}, feed_mm_per_min};
}

}  // namespace

TEST_GROUP(GcodeJob) {
  test::LoadedPart loaded{test::default_part(), 1};
};

TEST(GcodeJob, APlungeIntoTheTopIsRefusedAtItsDepthAndTheRetractIsNot) {
  CHECK(loaded.loaded);
  GcodeProgram program;
  program.moves = {feed(3, 25.0, 12.5, 6.5), feed(4, 25.0, 12.5, 5.5), feed(5, 25.0, 12.5, 6.5), feed(6, 27.0, 12.5, 6.5)};
  const std::vector<GcodeRefusal> refused = refused_lines(loaded.part, program, kStart);
  LONGS_EQUAL(1, refused.size());
  LONGS_EQUAL(4, refused[0].line);
  DOUBLES_EQUAL(0.5, refused[0].depth_mm, 1e-6);
}

TEST(GcodeJob, AMoveAlongTheTopAtDepthIsRefusedTooAndAChordsLineOnce) {
  GcodeProgram program;
  program.moves = {feed(3, 25.0, 12.5, 5.8), feed(4, 26.0, 12.5, 5.8), feed(4, 27.0, 12.5, 5.8), feed(5, 27.0, 12.5, 8.0)};
  const std::vector<GcodeRefusal> refused = refused_lines(loaded.part, program, kStart);
  LONGS_EQUAL(2, refused.size());
  LONGS_EQUAL(3, refused[0].line);
  LONGS_EQUAL(4, refused[1].line);  // two chords of one arc's line: listed once
  DOUBLES_EQUAL(0.2, refused[1].depth_mm, 1e-6);
}

TEST(GcodeJob, TouchingTheTopIsNotARefusal) {
  GcodeProgram program;
  program.moves = {feed(3, 25.0, 12.5, 6.0), feed(4, 27.0, 12.5, 6.0)};
  LONGS_EQUAL(0, refused_lines(loaded.part, program, kStart).size());
}

TEST(GcodeJob, TheScriptFollowsTheFeedsUnderTheTopSpeed) {
  GcodeProgram program;
  program.moves = {{3, GcodeMoveKind::Traverse, {25.0, 12.5, 8.0}, 0.0},  // 2 mm at the top speed: 1 s
                   feed(4, 25.0, 14.5, 8.0, 60.0),                          // 2 mm at 1 mm/s: 2 s
                   feed(5, 25.0, 16.5, 8.0, 6000.0)};                       // 100 mm/s, held to 2 mm/s: 1 s
  const stencil::sim::OperatorScript script = gcode_script(program, kStart, 2.0, 10.0);
  LONGS_EQUAL(4, script.t_s.size());
  DOUBLES_EQUAL(0.0, script.t_s[0], 1e-12);
  DOUBLES_EQUAL(1.0, script.t_s[1], 1e-9);
  DOUBLES_EQUAL(3.0, script.t_s[2], 1e-9);
  DOUBLES_EQUAL(4.0, script.t_s[3], 1e-9);
  DOUBLES_EQUAL(10.0 * 16.5, script.device_mm[3].y(), 1e-9);  // device = scale x world
}

TEST(GcodeJob, CutDirectlyTheProgramGougesAsDeepAsItGoes) {
  SimRig rig;
  GcodeProgram program;
  program.moves = {feed(3, 25.0, 12.5, 5.5), feed(4, 25.0, 12.5, 10.0)};
  SimResult result;
  cut_directly(loaded.part, default_stock(loaded.part), true_frames(rig), program, kStart, result);
  CHECK(result.started);
  CHECK(result.gouge_measured);
  DOUBLES_EQUAL(0.5, result.gouge_max_depth_mm, 1e-6);
  CHECK(result.removed_volume_mm3 > 0.0);
  CHECK(result.gouge_volume_mm3 > 0.0);
  LONGS_EQUAL(2, result.machine_updates);
}
