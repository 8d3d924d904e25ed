// What a display may ask of the controller, parsed from its WebSocket text messages and checked
// against the board's limits before anything reaches the cycle's command ring.
//
//   {"type":"set","name":"coupling"|"force_limit"|"speed_limit","value":N}
//   {"type":"reset"}
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "firmware/core/control/cycle_messages.hpp"

namespace stencil::hmi {

// A message longer than this is refused unread (the server closes a connection that sends a frame
// past it; see HmiServer).
inline constexpr std::size_t kMaxRequestBytes = 1024;

enum class RequestKind : std::uint8_t { Set, Reset };
enum class Parameter : std::uint8_t { Coupling, ForceLimit, SpeedLimit };

struct Request {
  RequestKind kind = RequestKind::Reset;
  Parameter parameter = Parameter::Coupling;
  double value = 0.0;
};

// The limits a parameter is checked against: the board's force limit and the mill's speed are the
// most the cycle will ever take (it clamps to them too); the coupling's range is the controller's.
struct HmiLimits {
  double board_force_limit_n = 5.0;
  double mill_speed_mm_per_s = 1.0;
  double min_coupling_n_per_device_mm = 0.05;
  double max_coupling_n_per_device_mm = 2.0;
};

[[nodiscard]] const char* parameter_unit(Parameter parameter);  // "N/mm", "N", "mm/s"
// The command that sets it; its name is control::parameter_name(command_kind(parameter)).
[[nodiscard]] control::CommandKind command_kind(Parameter parameter);

// False with `error` saying what was wrong and what was expected (never throws, whatever the bytes).
[[nodiscard]] bool parse_request(std::string_view text, Request& request, std::string& error);

// Why a Set request may not go to the cycle ("50 N is above the board's force limit of 5 N"), or ""
// when it may.
[[nodiscard]] std::string refusal(const Request& request, const HmiLimits& limits);

}  // namespace stencil::hmi
