#include "firmware/services/display_link/request_rules.hpp"

#include <cmath>
#include <cstdio>

#include "firmware/core/control/safe_state.hpp"

namespace stencil::display_link {
namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace

const char* parameter_unit(Parameter parameter) {
  switch (parameter) {
    case Parameter::Coupling:
      return "N/mm";
    case Parameter::ForceLimit:
      return "N";
    case Parameter::SpeedLimit:
      return "mm/s";
    case Parameter::Damping:
      return "N s/m";
    case Parameter::Friction:
    case Parameter::SpeedLimiting:
      return "";
  }
  return "";
}

control::CommandKind command_kind(Parameter parameter) {
  switch (parameter) {
    case Parameter::Coupling:
      return control::CommandKind::SetCoupling;
    case Parameter::ForceLimit:
      return control::CommandKind::SetForceLimit;
    case Parameter::SpeedLimit:
      return control::CommandKind::SetSpeedLimit;
    case Parameter::Damping:
      return control::CommandKind::SetDamping;
    case Parameter::Friction:
      return control::CommandKind::SetFriction;
    case Parameter::SpeedLimiting:
      return control::CommandKind::SetSpeedLimiting;
  }
  return control::CommandKind::SetCoupling;
}

control::Command command_of(const Request& request) {
  constexpr auto kDisplay = control::CommandSource::Display;
  switch (request.kind) {
    case RequestKind::Set:
      return {command_kind(request.parameter), request.value, kDisplay};
    case RequestKind::Reset:
      return {control::CommandKind::Reset, 0.0, kDisplay};
    case RequestKind::Stop:
      return {control::CommandKind::Stop, 0.0, kDisplay};
    case RequestKind::Pause:
      return {control::CommandKind::Pause, 0.0, kDisplay};
    case RequestKind::Resume:
      return {control::CommandKind::Resume, 0.0, kDisplay};
    case RequestKind::Start:
      break;  // never a cycle command (the request server takes it to the waiting program)
  }
  return {control::CommandKind::Stop, 0.0, kDisplay};  // not a command: a stop is the safe guess
}

std::string refusal(const Request& request, const RequestLimits& limits) {
  if (request.kind != RequestKind::Set) {
    return "";
  }
  const double value = request.value;
  const std::string unit = parameter_unit(request.parameter);
  const control::CommandKind kind = command_kind(request.parameter);
  if (request.parameter == Parameter::SpeedLimiting) {
    if (value != 0.0 && value != 1.0) {
      return "speed limiting " + number(value) + ": expected 0 (the cap) or 1 (the penalty)";
    }
  } else if (control::zero_allowed(kind)) {
    if (!std::isfinite(value) || value < 0.0) {
      return std::string(control::parameter_name(kind)) + " must be a number of at least 0";
    }
  } else if (!std::isfinite(value) || value <= 0.0) {
    return std::string(control::parameter_name(kind)) + " must be a positive number of " + unit;
  }
  switch (request.parameter) {
    case Parameter::Coupling:
      if (value < limits.min_coupling_n_per_device_mm || value > limits.max_coupling_n_per_device_mm) {
        return number(value) + " N/mm is outside the coupling's range of " + number(limits.min_coupling_n_per_device_mm) +
               " to " + number(limits.max_coupling_n_per_device_mm) + " N/mm";
      }
      break;
    case Parameter::ForceLimit:
      if (value > limits.board_force_limit_n) {
        return number(value) + " N is above the board's force limit of " + number(limits.board_force_limit_n) +
               " N (the operator must always be able to overpower the device)";
      }
      break;
    case Parameter::SpeedLimit:
      if (value > limits.mill_speed_mm_per_s) {
        return number(value) + " mm/s is above what the mill follows, " + number(limits.mill_speed_mm_per_s) + " mm/s";
      }
      break;
    case Parameter::Damping:
      if (value > limits.max_damping_n_s_per_m) {
        return number(value) + " N s/m is above the most damping the cycle takes, " +
               number(limits.max_damping_n_s_per_m) + " N s/m";
      }
      break;
    case Parameter::Friction:
      if (value > 1.0) {
        return "a friction coefficient of " + number(value) + " is outside 0 to 1";
      }
      break;
    case Parameter::SpeedLimiting:
      if (value != 0.0 && value != 1.0) {
        return "speed limiting " + number(value) + ": expected 0 (the cap) or 1 (the penalty)";
      }
      break;
  }
  return "";
}

std::string pause_refusal(RequestKind kind, bool have, const control::Telemetry& telemetry) {
  if (!have) {
    return "the job has not started yet";
  }
  if (telemetry.safe_reason != control::SafeReason::None) {
    return std::string("the cycle is in its safe state (") + control::safe_reason_name(telemetry.safe_reason) +
           "): nothing is moving";
  }
  if (kind == RequestKind::Pause && telemetry.paused) {
    return "already paused";
  }
  if (kind == RequestKind::Resume && !telemetry.paused) {
    return "not paused";
  }
  return "";
}

std::string reset_refusal(bool have, const control::Telemetry& telemetry, const ResetRule& rule) {
  if (!have || telemetry.safe_reason == control::SafeReason::None) {
    return "not in a safe state";
  }
  if (telemetry.device_still_s < rule.still_time_s) {
    return "hold the handle still (" + std::to_string(static_cast<int>(rule.still_time_s * 1000)) + " ms)";
  }
  if (telemetry.device_to_tool_mm > rule.reset_distance_mm) {
    char text[120];
    std::snprintf(text, sizeof text, "bring the handle to the virtual tool: %.1f mm away, at most %.1f mm",
                  telemetry.device_to_tool_mm, rule.reset_distance_mm);
    return text;
  }
  return "";
}

}  // namespace stencil::display_link
