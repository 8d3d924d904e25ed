#include "firmware/services/hmi/hmi_requests.hpp"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace stencil::hmi {
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
  }
  return control::CommandKind::SetCoupling;
}

bool parse_request(std::string_view text, Request& request, std::string& error) {
  if (text.size() > kMaxRequestBytes) {
    error = "message of " + std::to_string(text.size()) + " bytes: at most " + std::to_string(kMaxRequestBytes);
    return false;
  }
  const nlohmann::json message = nlohmann::json::parse(text, nullptr, false);
  if (message.is_discarded()) {
    error = "not JSON: expected {\"type\":\"set\"|\"reset\", ...}";
    return false;
  }
  if (!message.is_object() || !message.contains("type") || !message["type"].is_string()) {
    error = "expected an object with a string \"type\" (\"set\" or \"reset\")";
    return false;
  }
  const std::string type = message["type"].get<std::string>();
  if (type == "reset") {
    request = Request{RequestKind::Reset, Parameter::Coupling, 0.0};
    return true;
  }
  if (type != "set") {
    error = "unknown \"type\" '" + type.substr(0, 40) + "': expected \"set\" or \"reset\"";
    return false;
  }
  if (!message.contains("name") || !message["name"].is_string()) {
    error = "\"set\" needs a string \"name\": coupling, force_limit or speed_limit";
    return false;
  }
  const std::string name = message["name"].get<std::string>();
  Parameter parameter{};
  if (name == "coupling") {
    parameter = Parameter::Coupling;
  } else if (name == "force_limit") {
    parameter = Parameter::ForceLimit;
  } else if (name == "speed_limit") {
    parameter = Parameter::SpeedLimit;
  } else {
    error = "unknown parameter '" + name.substr(0, 40) + "': expected coupling, force_limit or speed_limit";
    return false;
  }
  if (!message.contains("value") || !message["value"].is_number()) {
    error = std::string("\"set\" ") + control::parameter_name(command_kind(parameter)) + " needs a number \"value\" in " +
            parameter_unit(parameter);
    return false;
  }
  request = Request{RequestKind::Set, parameter, message["value"].get<double>()};
  return true;
}

std::string refusal(const Request& request, const HmiLimits& limits) {
  if (request.kind != RequestKind::Set) {
    return "";
  }
  const double value = request.value;
  const std::string unit = parameter_unit(request.parameter);
  if (!std::isfinite(value) || value <= 0.0) {
    return std::string(control::parameter_name(command_kind(request.parameter))) + " must be a positive number of " + unit;
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
  }
  return "";
}

}  // namespace stencil::hmi
