// libFuzzer target: the rig's configuration file takes any bytes; a refusal names the file, and a
// file it accepts keeps the rig's ceilings (the force at most 5 N, the speed within the steps, the
// standoff the planner needs, Z homed first, every number finite; with LinuxCNC, at most 9 updates
// a second, the virtual tool within what the mill makes good, a longest move and a feed).
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
  require(f.machine_standoff_mm >= rig::standoff_needed_mm(f));
  if (f.controller == rig::MachineController::Linuxcnc) {
    // (Reached only with an INI on this disk that the input names: machine.linuxcnc.ini.)
    const stencil::motion::PlannerLimits limits = rig::planner_limits(f);
    require(f.machine_update_hz <= 9.0 && limits.path == stencil::motion::MachinePath::Straight);
    require(f.virtual_tool_speed_mm_per_s <= limits.speed.max_axis_speed_mm_per_s);
    require(stencil::motion::follow_fallback_fits(limits));
    const stencil::hal::linuxcnc::LinuxcncConfig link = rig::linuxcnc_config(f);
    require(link.max_move_mm > 0.0 && std::isfinite(link.max_move_mm) && link.feed_mm_per_min > 0.0);
    require(link.connect_password[0] != '\0' && link.enable_password[0] != '\0' && link.port >= 1);
    require(config.serial_port.empty());  // the CY545's keys are refused with LinuxCNC
  } else {
    require(f.max_speed_mm_per_s * f.steps_per_mm <= f.step_rate_steps_per_s + 1e-9);
    require(f.virtual_tool_speed_mm_per_s <= f.max_speed_mm_per_s);
    require(f.homing_order[0] == 2 && f.homing_order[1] != f.homing_order[2] && f.homing_order[1] < 2 &&
            f.homing_order[2] < 2);
    require(f.linuxcnc == rig::kRig.linuxcnc && config.linuxcnc_ini.source.empty());
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    require(std::isfinite(f.workspace_mm[axis]) && std::isfinite(f.backlash_mm[axis]));
    require(f.machine_sign[axis] == 1 || f.machine_sign[axis] == -1);
  }
  require(config.machine_priority < config.cycle_priority);
  return 0;
}
