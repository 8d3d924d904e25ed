// libFuzzer target: the rig's configuration file takes any bytes; a refusal names the file, and a
// file it accepts keeps the rig's ceilings (the force at most 5 N, the speed within the steps, the
// standoff the planner needs, Z homed first, every number finite).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "board/sherline_suzuki/rig_config.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;
namespace rig = stencil::board::sherline_suzuki;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  rig::RigConfig config;
  std::string error;
  if (!rig::parse_rig_config(text, "fuzz.toml", config, error)) {
    require(error.rfind("fuzz.toml", 0) == 0);
    require(config.facts == rig::kRig);  // nothing of a refused file is taken
    return 0;
  }
  const rig::RigFacts& f = config.facts;
  require(std::isfinite(f.force_limit_n) && f.force_limit_n <= 5.0);
  require(f.max_speed_mm_per_s * f.steps_per_mm <= f.step_rate_steps_per_s + 1e-9);
  require(f.virtual_tool_speed_mm_per_s <= f.max_speed_mm_per_s);
  require(f.machine_standoff_mm >= rig::standoff_needed_mm(f));
  require(f.homing_order[0] == 2 && f.homing_order[1] != f.homing_order[2] && f.homing_order[1] < 2 && f.homing_order[2] < 2);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    require(std::isfinite(f.workspace_mm[axis]) && std::isfinite(f.backlash_mm[axis]));
    require(f.machine_sign[axis] == 1 || f.machine_sign[axis] == -1);
  }
  require(config.machine_priority < config.cycle_priority);
  return 0;
}
