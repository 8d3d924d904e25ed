// Report comparison: a walk over both JSON trees at once.
#include "toolchain/same_behaviour/report_comparison.hpp"

#include <string_view>

namespace stencil::same_behaviour {
namespace {

// A value for a one-line message: its JSON text, cut short when long (an array of run endings).
std::string shown(const nlohmann::json& value) {
  constexpr std::size_t kLongest = 80;
  std::string text = value.dump();
  if (text.size() > kLongest) {
    text = text.substr(0, kLongest - 3) + "...";
  }
  return text;
}

std::string child(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

void compare(const nlohmann::json& older, const nlohmann::json& newer, const std::string& path, ReportComparison& out) {
  if (older.is_object() && newer.is_object()) {
    for (const auto& [key, value] : older.items()) {
      if (is_wall_clock_field(key)) {
        continue;
      }
      const auto found = newer.find(key);
      if (found == newer.end()) {
        out.changed.push_back(child(path, key) + ": removed (was " + shown(value) + ")");
      } else {
        compare(value, *found, child(path, key), out);
      }
    }
    for (const auto& [key, value] : newer.items()) {
      if (!is_wall_clock_field(key) && !older.contains(key)) {
        out.added.push_back(child(path, key) + " = " + shown(value));
      }
    }
    return;
  }
  if (older.is_array() && newer.is_array()) {
    if (older.size() != newer.size()) {
      out.changed.push_back(path + ": " + std::to_string(older.size()) + " elements -> " + std::to_string(newer.size()) +
                            " (" + shown(older) + " -> " + shown(newer) + ")");
      return;
    }
    for (std::size_t i = 0; i < older.size(); ++i) {
      compare(older[i], newer[i], path + "[" + std::to_string(i) + "]", out);
    }
    return;
  }
  if (older.is_string() && newer.is_string()) {
    if (without_start_time(older.get<std::string>()) != without_start_time(newer.get<std::string>())) {
      out.changed.push_back(path + ": " + shown(older) + " -> " + shown(newer));
    }
    return;
  }
  // Numbers compare exactly: the reports print doubles so that they read back to the same bits.
  if (older != newer) {
    out.changed.push_back((path.empty() ? std::string("the report") : path) + ": " + shown(older) + " -> " + shown(newer));
  }
}

}  // namespace

// With the wall clock, the report's provenance: which build made it and its command line, not the job.
bool is_wall_clock_field(const std::string& key) {
  return key == "wall_s" || key == "provenance" || key == "compute_us" || key == "memory_kb" || key.find("latency") != std::string::npos;
}

// By hand, not std::regex: GCC 12's <regex> does not build warning-free under the ASan preset.
std::string without_start_time(const std::string& text) {
  static constexpr std::string_view kPrefix = "stencil-sim-";
  static constexpr std::string_view kPattern = "########-######.journal";  // '#': a digit
  std::string out;
  std::size_t at = 0;
  for (;;) {
    const std::size_t found = text.find(kPrefix, at);
    if (found == std::string::npos) {
      out.append(text, at, std::string::npos);
      return out;
    }
    const std::size_t stamp = found + kPrefix.size();
    bool matches = stamp + kPattern.size() <= text.size();
    for (std::size_t i = 0; matches && i < kPattern.size(); ++i) {
      const char c = text[stamp + i];
      matches = kPattern[i] == '#' ? (c >= '0' && c <= '9') : c == kPattern[i];
    }
    out.append(text, at, stamp - at);
    if (matches) {
      out += "YYYYMMDD-HHMMSS.journal";
      at = stamp + kPattern.size();
    } else {
      at = stamp;
    }
  }
}

ReportComparison compare_reports(const nlohmann::json& older, const nlohmann::json& newer) {
  ReportComparison out;
  compare(older, newer, "", out);
  return out;
}

}  // namespace stencil::same_behaviour
