// What a display may ask of a controller, and the rules the controller checks each request
// against before it reaches the cycle's command ring (the cycle still clamps every value to the
// board's limits). Plain data and plain functions: no JSON, no sockets.
#pragma once

#include <cstdint>
#include <string>

#include "firmware/core/control/cycle_messages.hpp"

namespace stencil::display_link {

// Start is not a cycle command: it answers the program waiting to turn the spindle on (never the ring).
enum class RequestKind : std::uint8_t { Set, Reset, Stop, Pause, Resume, Start };
enum class Parameter : std::uint8_t { Coupling, ForceLimit, SpeedLimit, Damping, Friction, SpeedLimiting };
inline constexpr int kParameterCount = 6;

struct Request {
  RequestKind kind = RequestKind::Reset;
  Parameter parameter = Parameter::Coupling;
  double value = 0.0;
};

// The limits a parameter is checked against: the board's force limit and the mill's speed are the
// most the cycle will ever take (it clamps to them too); the coupling's range is the controller's.
struct RequestLimits {
  double board_force_limit_n = 5.0;
  double mill_speed_mm_per_s = 1.0;
  double min_coupling_n_per_device_mm = 0.05;
  double max_coupling_n_per_device_mm = 2.0;
  double max_damping_n_s_per_m = 100.0;
};

// The cycle's reset rule, as far as the threads around it can see it from its telemetry.
struct ResetRule {
  double still_time_s = 0.2;
  double reset_distance_mm = 2.0;
};

// "N/mm", "N", "mm/s", "N s/m", "" (friction: a coefficient), "" (speed limiting: 0 cap, 1 penalty)
[[nodiscard]] const char* parameter_unit(Parameter parameter);
// The command that sets it; its name is control::parameter_name(command_kind(parameter)).
[[nodiscard]] control::CommandKind command_kind(Parameter parameter);
[[nodiscard]] control::Command command_of(const Request& request);

// Why a Set request may not go to the cycle ("50 N is above the board's force limit of 5 N"), or ""
// when it may.
[[nodiscard]] std::string refusal(const Request& request, const RequestLimits& limits);

// Why a pause or a resume may not be asked now ("" when it may), from the newest telemetry: the
// cycle's state decides again when it takes it.
[[nodiscard]] std::string pause_refusal(RequestKind kind, bool have, const control::Telemetry& telemetry);

// Why a reset may not be asked now ("" when it may), from the newest telemetry (`have` false: none
// yet): the threads' decision; the cycle's rule has the last word.
[[nodiscard]] std::string reset_refusal(bool have, const control::Telemetry& telemetry, const ResetRule& rule);

}  // namespace stencil::display_link
