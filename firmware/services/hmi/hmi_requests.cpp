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

}  // namespace stencil::hmi
