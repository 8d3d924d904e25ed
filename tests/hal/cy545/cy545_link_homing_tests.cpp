// The CY545 link's homing order against the simulated CY545 on a pseudo-terminal: Z first (after a
// crash or a stop mid-cut the tool may stand in the stock, and only raising it first takes it out
// without ploughing sideways), then the others in the order configured. The machine side only asks
// the link to home (tests/control/machine_side_tests.cpp checks that it does, before the spindle
// starts); the order is the link's, so it is tested here.
#include <array>
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "board/sim/sim_facts.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/cy545/fake_cy545_clock.hpp"
#include "sim/mill/simulated_mill.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>

using namespace stencil;
using stencil::sim::Axis;
using stencil::sim::StepDirection;

namespace {

constexpr hal::MonotonicNs kMs = 1'000'000;

// The axes in the order they first moved: the mill's own account of every step (its motion observer).
struct FirstMoves final : sim::MillMotionObserver {
  std::vector<int> order;
  void axis_moved(Axis axis, const std::array<std::int64_t, sim::kMillAxisCount>& /*axis_steps*/) override {
    const int moved = static_cast<int>(axis);
    if (std::find(order.begin(), order.end(), moved) == order.end()) {
      order.push_back(moved);
    }
  }
};

// Homes the link on the simulated mill, every axis some way above its switch, on the fake chip's
// virtual clock (deterministic: no thread of the fake's, nothing a loaded host can starve): the axes
// in the order they first moved.
std::vector<int> axes_in_the_order_they_moved(const hal::cy545::Cy545Config& config) {
  sim::SimulatedMill mill{board::sim::kMillConfig};
  mill.place_axis(Axis::x, 40, StepDirection::positive);
  mill.place_axis(Axis::y, 30, StepDirection::positive);
  mill.place_axis(Axis::z, 50, StepDirection::positive);
  FirstMoves moves;
  mill.set_motion_observer(&moves);
  sim::cy545::FakeCy545 fake{mill, board::sim::kMmc4sWiring, 0};
  sim::cy545::FakeCy545Clock clock{fake, 0, board::sim::kBaud};
  hal::cy545::SerialPort port;
  char error[256] = {};
  CHECK_TEXT(port.open(fake.slave_path().c_str(), board::sim::kBaud, error), error);
  hal::cy545::Cy545Link link(port, clock, config);
  const hal::MachineResult started = link.start(clock.now_ns() + 2000 * kMs);
  CHECK_TEXT(started.done, link.last_error());
  const hal::MachineResult homed = link.home(clock.now_ns() + link.homing_bound_ns() + 1000 * kMs);
  CHECK_TEXT(homed.done, link.last_error());
  mill.set_motion_observer(nullptr);
  return moves.order;
}

hal::cy545::Cy545Config fast_homing_config() {
  hal::cy545::Cy545Config config = board::sherline_suzuki::kCy545;
  config.motion.homing_rate = 20000;  // quick in tests
  config.motion.homing_slow_rate = 5000;
  config.motion.homing_travel_steps = 2000;  // every axis starts within 200 steps of its switch
  return config;
}

}  // namespace

TEST_GROUP(Cy545LinkHoming){};

TEST(Cy545LinkHoming, TheRigHomesZFirstThenXThenY) {
  const hal::cy545::Cy545Config config = fast_homing_config();
  CHECK((std::array<std::uint8_t, 3>{2, 0, 1}) == config.motion.homing_order);  // the rig's facts: Z first
  CHECK((std::vector<int>{2, 0, 1}) == axes_in_the_order_they_moved(config));
}

// The order is the configuration's, not a fixed loop: a different one homes differently (so the
// test above would see a link that ignored it).
TEST(Cy545LinkHoming, AnotherConfiguredOrderIsFollowedAsGiven) {
  hal::cy545::Cy545Config config = fast_homing_config();
  config.motion.homing_order = {2, 1, 0};
  CHECK((std::vector<int>{2, 1, 0}) == axes_in_the_order_they_moved(config));
}
