// libFuzzer target: linuxcncrsh's replies (hal/linuxcnc/linuxcncrsh_replies.hpp) from any bytes on the
// line: each parser reads only its input, a value is a word of the line, a position is three finite
// numbers, an error's words lie inside the line, and a refused line leaves what it was handed alone.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/linuxcnc/linuxcncrsh_replies.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

namespace {

bool inside(std::string_view part, std::string_view whole) {
  return part.data() >= whole.data() && part.data() + part.size() <= whole.data() + whole.size();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::hal::linuxcnc;
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  const SetReply set = set_reply(line, "MDI");
  require(set == SetReply::Other || line.find("MDI") != std::string_view::npos);
  static_cast<void>(hello_accepted(line));
  const std::string_view value = value_of(line, "ESTOP");
  require(value.empty() || (inside(value, line) && value.find(' ') == std::string_view::npos));
  std::array<double, 3> xyz{7.0, 8.0, 9.0};
  if (parse_xyz(line, "ABS_ACT_POS", xyz)) {
    require(std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2]));
  } else {
    require(xyz[0] == 7.0 && xyz[1] == 8.0 && xyz[2] == 9.0);
  }
  std::array<bool, 3> homed{true, false, true};
  if (!parse_joints_homed(line, homed)) {
    require(homed[0] && !homed[1] && homed[2]);
  }
  std::string_view words;
  if (parse_error(line, words) == ErrorReply::Error) {
    require(!words.empty() && inside(words, line) && words != "OK");
  }
  return 0;
}
