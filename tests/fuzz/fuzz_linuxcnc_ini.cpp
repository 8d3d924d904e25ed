// libFuzzer target: LinuxCNC's INI as the rig reads it (board/sherline_suzuki/linuxcnc_ini.hpp) takes
// any bytes; a refusal names the file and takes nothing, and an INI it accepts has finite, positive
// speeds and accelerations, soft limits that open an interval, lines for what it read, and
// linuxcncrsh's passwords as words of its own (never its defaults); the checks against a rig's
// travel and passwords answer for any of them.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "board/sherline_suzuki/linuxcnc_ini.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;
namespace rig = stencil::board::sherline_suzuki;

namespace {

bool one_word(const std::string& password) {
  bool word = !password.empty();
  for (const char c : password) word = word && c != ' ' && c != '\t' && c != '\r' && c != '\n';
  return word;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  rig::LinuxcncIni ini;
  std::string error;
  if (!rig::parse_linuxcnc_ini(text, "fuzz.ini", ini, error)) {
    require(error.rfind("fuzz.ini", 0) == 0);
    require(ini.source.empty() && ini.display.line == 0);  // nothing of a refused file is taken
    return 0;
  }
  require(error.empty() && ini.source == "fuzz.ini" && ini.size == size);
  for (const rig::LinuxcncIniAxis& axis : ini.axes) {
    require(std::isfinite(axis.max_velocity_mm_per_s.value) && axis.max_velocity_mm_per_s.value > 0.0);
    require(std::isfinite(axis.max_acceleration_mm_per_s2.value) && axis.max_acceleration_mm_per_s2.value > 0.0);
    require(std::isfinite(axis.min_limit_mm.value) && axis.min_limit_mm.value < axis.max_limit_mm.value);
    require(axis.max_velocity_mm_per_s.line > 0 && axis.max_acceleration_mm_per_s2.line > 0 && axis.min_limit_mm.line > 0 &&
            axis.max_limit_mm.line > 0);
  }
  require(ini.max_linear_velocity_mm_per_s.line == 0 ? ini.max_linear_velocity_mm_per_s.value == 0.0
                                                       : ini.max_linear_velocity_mm_per_s.value > 0.0);
  require(ini.display.line > 0 && ini.display.port >= 1);
  require(one_word(ini.display.connect_password) && one_word(ini.display.enable_password));
  require(ini.display.connect_password != "EMC" && ini.display.enable_password != "EMCTOO");
  const std::string travel = rig::linuxcnc_travel_outside_limits(ini, {50.0, 25.0, 25.0});
  require(travel.empty() || travel.rfind("fuzz.ini:", 0) == 0);
  require(rig::linuxcnc_display_disagreement(ini, ini.display.port, ini.display.connect_password,
                                             ini.display.enable_password).empty());
  const std::string other = rig::linuxcnc_display_disagreement(ini, 5007, "SimMillHello", "SimMillEnable");
  require(other.empty() || other.rfind("fuzz.ini:", 0) == 0);
  return 0;
}
