// Tool notation parsing, strict: unknown keys, repeated keys and bad numbers are errors.
#include "toolchain/tablegen/tool_option.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <string_view>

#include "toolchain/tablegen/input_error.hpp"

namespace stencil::tablegen {
namespace {

std::map<std::string, double> parse_keys(std::string_view text, const std::string& option, const std::string& allowed) {
  std::map<std::string, double> values;
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    const std::string_view item = text.substr(0, comma);
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    const std::size_t equals = item.find('=');
    if (equals == std::string_view::npos) {
      throw InputError(option + ": '" + std::string(item) + "': expected key=value with a key from " + allowed);
    }
    const std::string key(item.substr(0, equals));
    const std::string_view value_text = item.substr(equals + 1);
    if (key.size() != 1 || allowed.find(key) == std::string::npos) {
      throw InputError(option + ": unknown key '" + key + "'; expected one of " + allowed);
    }
    if (values.count(key) != 0) {
      throw InputError(option + ": key '" + key + "' given twice");
    }
    double value = 0.0;
    const auto [end, error] = std::from_chars(value_text.data(), value_text.data() + value_text.size(), value);
    if (value_text.empty() || error != std::errc() || end != value_text.data() + value_text.size() ||
        !std::isfinite(value)) {
      throw InputError(option + ": " + key + "='" + std::string(value_text) + "': expected a finite number of millimetres");
    }
    values[key] = value;
  }
  return values;
}

}  // namespace

geometry::ToolSpec parse_tool(const std::string& tool_text, const std::string& holder_text) {
  const std::size_t colon = tool_text.find(':');
  const std::string kind = tool_text.substr(0, colon);
  geometry::ToolSpec spec{};
  std::string allowed;
  if (kind == "flat") {
    spec.kind = geometry::CutterKind::Flat;
    allowed = "d, l";
  } else if (kind == "ball") {
    spec.kind = geometry::CutterKind::Ball;
    allowed = "d, l";
  } else if (kind == "bull") {
    spec.kind = geometry::CutterKind::BullNose;
    allowed = "d, r, l";
  } else {
    throw InputError("--tool '" + tool_text + "': expected flat:d=D[,l=L], ball:d=D[,l=L] or bull:d=D,r=RC[,l=L]");
  }
  const auto values = parse_keys(colon == std::string::npos ? std::string_view{} : std::string_view(tool_text).substr(colon + 1),
                                 "--tool", allowed);
  if (values.count("d") == 0) {
    throw InputError("--tool '" + tool_text + "': the diameter d=D is required");
  }
  if (spec.kind == geometry::CutterKind::BullNose && values.count("r") == 0) {
    throw InputError("--tool '" + tool_text + "': a bull-nose needs its corner radius r=RC");
  }
  spec.diameter_mm = values.at("d");
  spec.flute_length_mm = values.count("l") != 0 ? values.at("l") : 4.0 * spec.diameter_mm;
  spec.corner_radius_mm = values.count("r") != 0 ? values.at("r") : 0.0;
  const auto holder = parse_keys(holder_text, "--holder", "d, l");
  spec.holder_diameter_mm = holder.count("d") != 0 ? holder.at("d") : kDefaultHolderDiameter_mm;
  spec.holder_length_mm = holder.count("l") != 0 ? holder.at("l") : kDefaultHolderLength_mm;
  return spec;
}

}  // namespace stencil::tablegen
