// libFuzzer target: the operator display's request parser and the limits check behind it, on any
// bytes a browser (or anyone on the network) could send: never a crash, an error whenever it says
// no, and never a parameter past the board's limits let through.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "firmware/services/hmi/hmi_requests.hpp"
#include "firmware/services/hmi/hmi_server.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "tests/fuzz/fuzz_require.hpp"

using stencil::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace stencil::hmi;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // The server's whole answer, as a client would get it: always valid JSON, never an exception.
  static const stencil::tables::PartTables part{};
  static HmiServer server({}, part, stencil::control::ControllerConfig{});
  for (const bool may_control : {false, true}) {
    const nlohmann::json answer = nlohmann::json::parse(server.handle_message(may_control, text), nullptr, false);
    require(answer.is_object() && answer.contains("type"));
  }
  stencil::control::Command command{};
  while (server.pop_command(command)) {
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
    require(std::isfinite(request.value) && request.value > 0.0);
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
    }
  }
  return 0;
}
