// libFuzzer target: the simulated operator's CSV reader takes any bytes, and a script it accepts keeps
// its promises (finite numbers, times increasing, one angle pair per row), or it names the line.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "sim/operator/operator_script.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  stencil::sim::OperatorScript script;
  std::string error;
  if (!stencil::sim::parse_operator_csv(in, "fuzz.csv", script, error)) {
    require(error.rfind("fuzz.csv: ", 0) == 0);
    return 0;
  }
  require(error.empty() && !script.t_s.empty());
  require(script.t_s.size() == script.device_mm.size() && script.t_s.size() == script.angles_rad.size());
  for (std::size_t i = 0; i < script.t_s.size(); ++i) {
    require(std::isfinite(script.t_s[i]) && script.device_mm[i].allFinite() && script.angles_rad[i].allFinite());
    require(i == 0 || script.t_s[i] > script.t_s[i - 1]);
  }
  // Where the script is at any time stays finite, at its ends and in between.
  require(script.position_at(script.t_s.front() - 1.0).allFinite());
  require(script.position_at(0.5 * (script.t_s.front() + script.t_s.back())).allFinite());
  require(script.position_at(script.t_s.back() + 1.0).allFinite());
  return 0;
}
