// The simulation board's facts: the Sherline rig's (board/sherline_suzuki/rig_facts.hpp), and where the
// simulation deliberately differs, derived from the rig's with the reason. No number of its own.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "firmware/core/motion/machine_planner.hpp"
#include "hal/clock.hpp"
#include "hal/cy545/cy545_link.hpp"
#include "hal/haptic_device.hpp"
#include "sim/mill/simulated_mill.hpp"

namespace stencil::board::sim {

namespace rig = board::sherline_suzuki;

// The simulated rig: what the controller is configured with (stencil-sim --config: a rig's
// configuration file; by default the compiled-in Sherline/Suzuki rig), where the tool tip is in the
// world at home, and the simulated mill's truth (--mill-truth: the same file by default, another
// where a test wants the configuration wrong against the mill).
struct SimRig {
  rig::RigFacts facts = rig::kRig;
  std::array<double, 3> home_world_mm = rig::kHomeWorldMm;
  rig::RigFacts mill_truth = rig::kRig;
};

// The frames, speeds, planner, standoff and model cell of a job come from its SimRig (sim_job.hpp's
// functions of it); the constants below are the compiled-in rig's, for what is built before a job is.

// The simulated device samples at the compiled-in cycle's rate (device_process: --device-process).
inline constexpr hal::MonotonicNs kPeriodNs = rig::kPeriodNs;

// The serial line: the rig's baud rate (the port opens at it; on virtual time the fake's bytes take
// their wire time at it).
inline constexpr std::uint32_t kBaud = rig::kRig.serial_baud;

// The simulated Sherline mill: the rig's steps, backlash, hard stops and home switches as the mill
// really is (`truth`, which a test may make differ from what the controller's configuration says:
// the driver applies the configured wiring on its side of the line); it powers up in mid-workspace with the slack on the negative side (as after a positive
// move), so that homing has a way to go on every axis. Its direction lines are wired as the truth's
// step_direction says: where the configuration says otherwise, that axis runs the other way from
// what the driver commands.
inline constexpr stencil::sim::MillConfig mill_config(const rig::RigFacts& truth) {
  stencil::sim::MillConfig config{};
  config.steps_per_mm = truth.steps_per_mm;
  for (int axis = 0; axis < rig::kAxisCount; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    stencil::sim::MillAxisConfig& c = config.axes[a];
    c.backlash_steps = rig::backlash_steps(axis, truth);
    c.travel_min_steps = rig::mm_to_steps(rig::travel_min_mm(axis, truth), truth);
    c.travel_max_steps = rig::mm_to_steps(rig::travel_max_mm(axis, truth), truth);
    c.home_switch_edge_steps = rig::mm_to_steps(truth.home_switch_edge_mm, truth);
    c.initial_position_steps = rig::mm_to_steps(truth.workspace_mm[a] / 2.0, truth);
    c.motor_direction = truth.mmc4s.step_direction[a];  // the mill's direction lines as they are wired
  }
  return config;
}
inline constexpr stencil::sim::MillConfig kMillConfig = mill_config(rig::kRig);

// The MMC-4S board's wiring, for the fake CY545's board and the driver alike: the rig's.
inline constexpr hal::cy545::Mmc4sWiring kMmc4sWiring = rig::kRig.mmc4s;

// The CY545 driver as the simulation runs it: the rig's configuration, with these differences.
inline constexpr hal::cy545::Cy545Config link_config(bool realtime, const rig::RigFacts& facts = rig::kRig) {
  hal::cy545::Cy545Config config = rig::cy545_config(facts);
  // Homing at 25 times the rig's approach rate and 10 times its edge-finding rate: the simulated mill
  // has no inertia to overrun its switch with, and every job starts by homing from mid-travel.
  // (At most the chip's 27000 steps/s, whatever rates a configuration gives.)
  config.motion.homing_rate = 25 * config.motion.homing_rate < 27000U ? 25 * config.motion.homing_rate : 27000U;
  config.motion.homing_slow_rate =
      10 * config.motion.homing_slow_rate < 27000U ? 10 * config.motion.homing_slow_rate : 27000U;
  // The simulated rig takes the thesis's reading of the MMC-4S (an address latch: one select a change
  // of axis): the per-line reading's extra commands cost the mill much of its throughput (the demo
  // job: 0.93 % -> 5.4 % uncut). The driver is held to the per-line board by its own tests.
  config.wiring.channel_lines_latch_data = false;
  // Nor does it take the chip's per-command time (an assumption of 1 ms, unmeasured) and the driver's
  // settle against it: measured on the demo job they cost 0.93 % -> 1.72 % of the stock left uncut.
  // hal_cy545_tests hold the driver's pacing to that chip on virtual time; the rig keeps its settle.
  config.command_settle_ns = 0;
  if (realtime) {
    // The fake answers from a thread on a host that is not real-time: a late reply is its scheduling,
    // so five times the driver's own bound.
    config.reply_timeout_ns = 5 * config.reply_timeout_ns;
  }
  return config;
}
static_assert(link_config(false).motion.homing_rate == 20000 && link_config(false).motion.homing_slow_rate == 2000 &&
              link_config(true).reply_timeout_ns == 250'000'000);

}  // namespace stencil::board::sim
