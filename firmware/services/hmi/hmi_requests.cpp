#include "firmware/services/hmi/hmi_requests.hpp"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace stencil::hmi {
bool parse_request(std::string_view text, Request& request, std::string& error) {
  if (text.size() > kMaxRequestBytes) {
    error = "message of " + std::to_string(text.size()) + " bytes: at most " + std::to_string(kMaxRequestBytes);
    return false;
  }
  const nlohmann::json message = nlohmann::json::parse(text, nullptr, false);
  if (message.is_discarded()) {
    error = "not JSON: expected {\"type\":\"set\"|\"reset\"|\"stop\"|\"pause\"|\"resume\", ...}";
    return false;
  }
  if (!message.is_object() || !message.contains("type") || !message["type"].is_string()) {
    error = "expected an object with a string \"type\" (\"set\", \"reset\", \"stop\", \"pause\" or \"resume\")";
    return false;
  }
  const std::string type = message["type"].get<std::string>();
  const struct {
    const char* name;
    RequestKind kind;
  } plain[] = {{"reset", RequestKind::Reset},
               {"stop", RequestKind::Stop},
               {"pause", RequestKind::Pause},
               {"resume", RequestKind::Resume}};
  for (const auto& known : plain) {
    if (type == known.name) {
      request = Request{known.kind, Parameter::Coupling, 0.0};
      return true;
    }
  }
  if (type != "set") {
    error = "unknown \"type\" '" + type.substr(0, 40) + "': expected \"set\", \"reset\", \"stop\", \"pause\" or \"resume\"";
    return false;
  }
  constexpr const char* kNames = "coupling, force_limit, speed_limit, damping, friction or speed_limiting";
  if (!message.contains("name") || !message["name"].is_string()) {
    error = std::string("\"set\" needs a string \"name\": ") + kNames;
    return false;
  }
  const std::string name = message["name"].get<std::string>();
  Parameter parameter{};
  bool known = false;
  for (int p = 0; p < display_link::kParameterCount; ++p) {
    if (name == control::parameter_name(command_kind(static_cast<Parameter>(p)))) {
      parameter = static_cast<Parameter>(p);
      known = true;
    }
  }
  if (!known) {
    error = "unknown parameter '" + name.substr(0, 40) + "': expected " + kNames;
    return false;
  }
  // The speed limiting by its name as well as its number: "cap" (0) or "penalty" (1).
  if (parameter == Parameter::SpeedLimiting && message.contains("value") && message["value"].is_string()) {
    const std::string mode = message["value"].get<std::string>();
    if (mode != "cap" && mode != "penalty") {
      error = "speed_limiting '" + mode.substr(0, 40) + "': expected \"cap\" or \"penalty\" (or 0 or 1)";
      return false;
    }
    request = Request{RequestKind::Set, parameter, mode == "cap" ? 0.0 : 1.0};
    return true;
  }
  if (!message.contains("value") || !message["value"].is_number()) {
    const std::string unit = parameter_unit(parameter);
    error = std::string("\"set\" ") + control::parameter_name(command_kind(parameter)) + " needs a number \"value\"" +
            (unit.empty() ? std::string() : " in " + unit);
    return false;
  }
  request = Request{RequestKind::Set, parameter, message["value"].get<double>()};
  return true;
}

}  // namespace stencil::hmi
