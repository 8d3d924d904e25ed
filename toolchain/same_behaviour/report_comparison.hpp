// Two reports of the same job compared field by field, the wall-clock fields left out: what
// changed or went fails, what only the newer report has is listed as added.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace stencil::same_behaviour {

struct ReportComparison {
  std::vector<std::string> changed;  // "path: old -> new", and "path: removed (was old)"; any fails
  std::vector<std::string> added;    // "path = value": only in the newer report; allowed
};

// Measured on the wall clock, so never the same twice: `wall_s`, `compute_us`, `memory_kb` and any
// key naming a latency (`wakeup_latency_us`), at any depth. Also the default journal's name, which
// is the start time (stencil-sim-YYYYMMDD-HHMMSS.journal), inside any string.
[[nodiscard]] bool is_wall_clock_field(const std::string& key);
[[nodiscard]] std::string without_start_time(const std::string& text);

// Paths are dotted keys with [index] for array elements: `machine.stop_confirmed`, `job.run_endings[1].ending`.
[[nodiscard]] ReportComparison compare_reports(const nlohmann::json& older, const nlohmann::json& newer);

}  // namespace stencil::same_behaviour
