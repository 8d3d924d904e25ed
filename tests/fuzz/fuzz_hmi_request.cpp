// libFuzzer target: the operator display's (stencil-display's) request parser and the limits check behind it, on any
// bytes a browser (or anyone on the network) could send: never a crash, an error whenever it says
// no, and never a parameter past the board's limits let through.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "firmware/services/hmi/hmi_requests.hpp"
#include "firmware/services/hmi/display_app.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::hmi;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // The display's whole answer, as a browser would get it: always valid JSON, never an exception
  // (with no controller behind it, every request it would forward is refused, with the reason).
  static DisplayApp display([] {
    DisplayAppOptions options;
    options.controller_socket = "/nonexistent/display.sock";
    options.quiet = true;
    return options;
  }());
  for (const bool may_control : {false, true}) {
    const nlohmann::json answer = nlohmann::json::parse(display.handle_message(1, may_control, text), nullptr, false);
    require(answer.is_object() && answer.contains("type"));
  }
  Request request;
  std::string error;
  if (!parse_request(text, request, error)) {
    require(!error.empty());
    return 0;
  }
  require(size <= kMaxRequestBytes);
  const HmiLimits limits;
  const std::string refused = refusal(request, limits);
  if (request.kind == RequestKind::Set && refused.empty()) {
    require(std::isfinite(request.value) &&
            (request.value > 0.0 || (request.value == 0.0 && stencil::control::zero_allowed(command_kind(request.parameter)))));
    switch (request.parameter) {
      case Parameter::ForceLimit:
        require(request.value <= limits.board_force_limit_n);
        break;
      case Parameter::SpeedLimit:
        require(request.value <= limits.mill_speed_mm_per_s);
        break;
      case Parameter::Coupling:
        require(request.value >= limits.min_coupling_n_per_device_mm && request.value <= limits.max_coupling_n_per_device_mm);
        break;
      case Parameter::Damping:
        require(request.value <= limits.max_damping_n_s_per_m);
        break;
      case Parameter::Friction:
        require(request.value <= 1.0);
        break;
      case Parameter::SpeedLimiting:
        require(request.value == 0.0 || request.value == 1.0);
        break;
    }
  }
  return 0;
}
