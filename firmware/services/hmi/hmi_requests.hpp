// What a display's browser may ask, parsed from its WebSocket text messages (JSON) in
// stencil-display, and checked against the controller's limits before it goes to the controller
// (which checks again: display_link/request_rules.hpp).
//
//   {"type":"set","name":"coupling"|"force_limit"|"speed_limit"|"damping"|"friction","value":N}
//   {"type":"set","name":"speed_limiting","value":"cap"|"penalty"}   (or 0 or 1)
//   {"type":"reset"}
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "firmware/services/display_link/request_rules.hpp"

namespace stencil::hmi {

using display_link::command_kind;
using display_link::Parameter;
using display_link::parameter_unit;
using display_link::refusal;
using display_link::Request;
using display_link::RequestKind;
using HmiLimits = display_link::RequestLimits;

// A message longer than this is refused unread (the web server closes a connection whose frame
// header declares more).
inline constexpr std::size_t kMaxRequestBytes = 1024;

// False with `error` saying what was wrong and what was expected (never throws, whatever the bytes).
[[nodiscard]] bool parse_request(std::string_view text, Request& request, std::string& error);

}  // namespace stencil::hmi
