// The simulation's machine when it is the real LinuxCNC (board/sim/linuxcnc_wiring): halsampler's
// lines read as sim/linuxcnc_mill's sampler writes them, and the ground truth they make: every
// millisecond's step cut into the machined part, with its gouge; lost samples counted; what the last
// sample says of the machine is what the machinist finds. Against the real LinuxCNC: e2e
// linuxcnc_* (tests/e2e/sim_linuxcnc.sh).
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

#include "board/sim/linuxcnc_wiring.hpp"
#include "board/sim/sim_job.hpp"
#include "tests/support/loaded_part.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using namespace stencil::board::sim;

namespace {

template <std::size_t N>
void put(std::array<char, N>& field, const char* text) {
  field = {};
  std::snprintf(field.data(), N, "%s", text);
}

struct Machine {
  test::LoadedPart loaded{test::default_part(), 1};
  SimJob job;
  char path[64] = "/tmp/stencil-samples-XXXXXX";
  int fd = ::mkstemp(path);
  Machine() {
    job.part = &loaded.part;
    job.stock = default_stock(loaded.part);
    LinuxcncMill mill;
    put(mill.link.address, "127.0.0.1");
    put(mill.link.connect_password, "hello-pw");
    put(mill.link.enable_password, "enable-pw");
    mill.link.travel_mm = {50.0, 25.0, 25.0};
    mill.link.max_move_mm = 0.2;
    mill.samples_path = path;
    job.linuxcnc = mill;
  }
  ~Machine() {
    ::close(fd);
    ::unlink(path);
  }
  // Machine mm of a world point, in the frames the wiring uses.
  Eigen::Vector3d machine_mm(const Eigen::Vector3d& world) const {
    const motion::MachineFrames frames = true_frames(job.rig);
    Eigen::Vector3d mm;
    for (int i = 0; i < 3; ++i) {
      mm[i] = (world[i] - frames.home_world_mm[i]) * frames.machine_sign[static_cast<std::size_t>(i)];
    }
    return mm;
  }
  void append(const std::string& text) const {
    CHECK_EQUAL(static_cast<ssize_t>(text.size()), ::write(fd, text.data(), text.size()));
  }
  // Samples number `first` on, every millisecond's step of a straight line from `a` to `b` (world mm).
  std::uint64_t line(std::uint64_t first, const Eigen::Vector3d& a, const Eigen::Vector3d& b, int steps,
                     bool machine_on = true) const {
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector3d mm = machine_mm(a + (b - a) * (static_cast<double>(k) / steps));
      char text[200];
      std::snprintf(text, sizeof text, "%llu %.6f %.6f %.6f %.6f %.6f %.6f 1000.000000 %d 1\n",
                    static_cast<unsigned long long>(first + static_cast<std::uint64_t>(k)), mm.x(), mm.y(), mm.z(),
                    mm.x(), mm.y(), mm.z(), machine_on ? 1 : 0);
      append(text);
    }
    return first + static_cast<std::uint64_t>(steps) + 1;
  }
};

}  // namespace

TEST_GROUP(LinuxcncWiring){};

TEST(LinuxcncWiring, ASampleLineIsItsNumberPositionsCommandsAndBits) {
  LinuxcncSample sample{};
  CHECK(parse_linuxcnc_sample("10445 1.970000 0.000000 2.500000 2.0 0.0 2.5 1000.000000 1 0", sample));
  CHECK_EQUAL(10445U, sample.number);
  DOUBLES_EQUAL(1.97, sample.position_mm[0], 0.0);
  DOUBLES_EQUAL(2.5, sample.position_mm[2], 0.0);
  CHECK(sample.machine_on);
  CHECK_FALSE(sample.spindle_on);
  CHECK_FALSE(parse_linuxcnc_sample("overrun", sample));
  CHECK_FALSE(parse_linuxcnc_sample("10445 1.97 0.0", sample));  // torn by the end of the file
  CHECK_FALSE(parse_linuxcnc_sample("10445 1 2 3 4 5 6 7 1 0 extra", sample));
}

TEST(LinuxcncWiring, AToolThatWentIntoThePartIsAGougeInTheGroundTruthAndOneAboveItIsNone) {
  Machine above;
  const Eigen::Vector3d centre = 0.5 * (above.job.stock.low_mm + above.job.stock.high_mm);
  const Eigen::Vector3d high(centre.x(), centre.y(), above.job.stock.high_mm.z() + 1.0);
  {
    LinuxcncWiring mill(above.job);
    STRCMP_EQUAL("", mill.error().c_str());
    above.line(1, high, high, 5);  // before homing: skipped
    mill.arm();
    above.line(7, high, high + Eigen::Vector3d(3.0, 1.0, 0.0), 400);
    SimResult result;
    mill.leave(result, true, 0);
    DOUBLES_EQUAL(0.0, mill.machined().max_gouge_mm(), 0.0);
    CHECK_EQUAL(401U, mill.samples());
    CHECK_EQUAL(0U, mill.samples_lost());
    CHECK(result.mill_drivers_on_after_stop);  // the last sample's machine-on bit
  }
  Machine into;
  {
    LinuxcncWiring mill(into.job);
    mill.arm();
    const Eigen::Vector3d low(centre.x(), centre.y(), into.job.stock.low_mm.z() + 1.0);  // inside the prism
    into.line(1, high, low, 400, false);
    SimResult result;
    mill.leave(result, true, 0);
    CHECK(mill.machined().gouge_measured());
    CHECK(mill.machined().max_gouge_mm() > 1.0);
    CHECK_FALSE(result.mill_drivers_on_after_stop);
  }
}

TEST(LinuxcncWiring, LostSamplesAreCountedOverrunsAndGapsAlike) {
  Machine m;
  const Eigen::Vector3d high = m.job.stock.high_mm + Eigen::Vector3d(0.0, 0.0, 1.0);
  LinuxcncWiring mill(m.job);
  mill.arm();
  m.line(1, high, high, 9);          // 1..10
  m.append("overrun\n");
  m.line(15, high, high, 4);         // 15..19: 11..14 lost
  SimResult result;
  mill.leave(result, true, 0);
  CHECK_EQUAL(15U, mill.samples());
  CHECK_EQUAL(5U, mill.samples_lost());  // the overrun line, and the four missing numbers
}

TEST(LinuxcncWiring, ALinkConfigurationThatWouldBeRefusedIsTheWiringsErrorBeforeAnythingStarts) {
  Machine m;
  put(m.job.linuxcnc->link.connect_password, "EMC");
  LinuxcncWiring mill(m.job);
  STRCMP_CONTAINS("default passwords", mill.error().c_str());
  m.job.linuxcnc->samples_path = "/nonexistent/samples.txt";
  put(m.job.linuxcnc->link.connect_password, "hello-pw");
  LinuxcncWiring unread(m.job);
  STRCMP_CONTAINS("cannot read /nonexistent/samples.txt", unread.error().c_str());
}
