#include "board/sherline_suzuki/table_fit.hpp"

#include <algorithm>
#include <cstdio>

namespace stencil::board::sherline_suzuki {
namespace {

// A hair of rounding: the generator places parts touching the workspace's faces.
constexpr double kSlackMm = 1e-6;

std::string span(char axis, double low, double high) {
  char text[96];
  std::snprintf(text, sizeof text, "%c %g to %g mm", axis, low, high);
  return text;
}

// The tip's travel on `axis`, world mm: machine 0..travel counts from the home's world position along
// machine_sign; a tool that sticks out further than the touch-off's sits lower.
void travel_of(int axis, const RigFacts& facts, const TableFitJob& job, double& low, double& high) {
  const auto a = static_cast<std::size_t>(axis);
  const double lower_tip = axis == 2 ? job.tool_stick_out_mm - job.reference_stick_out_mm : 0.0;
  const double home = job.home_world_mm[a] - lower_tip;
  const double far = home + facts.machine_sign[a] * facts.workspace_mm[a];
  low = std::min(home, far);
  high = std::max(home, far);
}

}  // namespace

void configured_travel(const RigFacts& facts, const TableFitJob& job, std::array<double, 3>& low_mm,
                       std::array<double, 3>& high_mm) {
  for (int axis = 0; axis < 3; ++axis) {
    travel_of(axis, facts, job, low_mm[static_cast<std::size_t>(axis)], high_mm[static_cast<std::size_t>(axis)]);
  }
}

bool check_stock_fit(const std::array<double, 3>& low_mm, const std::array<double, 3>& high_mm, const RigFacts& facts,
                     const TableFitJob& job, std::string& error) {
  for (int axis = 0; axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    double travel_low = 0.0, travel_high = 0.0;
    travel_of(axis, facts, job, travel_low, travel_high);
    if (low_mm[a] < travel_low - kSlackMm || high_mm[a] > travel_high + kSlackMm) {
      error = "the stock spans " + span(static_cast<char>('x' + axis), low_mm[a], high_mm[a]) +
              "; the configured travel reaches " + span(static_cast<char>('x' + axis), travel_low, travel_high) +
              " (machine.travel_mm from the work offset)";
      return false;
    }
  }
  return true;
}

bool check_tables_fit(const tables::TableHeader& header, const std::string& tables_name, const RigFacts& facts,
                      const TableFitJob& job, std::string& error) {
  for (int axis = 0; axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    const char name = static_cast<char>('x' + axis);
    const double part_low = header.part_min_mm[a], part_high = header.part_max_mm[a];
    double travel_low = 0.0, travel_high = 0.0;
    travel_of(axis, facts, job, travel_low, travel_high);
    if (part_low < travel_low - kSlackMm || part_high > travel_high + kSlackMm) {
      error = tables_name + ": the part spans " + span(name, part_low, part_high) + "; the configured travel reaches " +
              span(name, travel_low, travel_high) + " (machine.travel_mm from the work offset)";
      return false;
    }
    const double reach_high = facts.haptic_workspace_mm[a] / facts.haptic_to_machine_scale;
    if (part_low < -kSlackMm || part_high > reach_high + kSlackMm) {
      error = tables_name + ": the part spans " + span(name, part_low, part_high) + "; the device reaches " +
              span(name, 0.0, reach_high) + " (haptic.reach_mm / haptic.device_mm_per_machine_mm)";
      return false;
    }
  }
  if (job.tool_stick_out_mm > 0.0 && header.tool_flute_length_mm > job.tool_stick_out_mm + kSlackMm) {
    char text[200];
    std::snprintf(text, sizeof text,
                  ": the tables' tool has %g mm of flutes below its holder; it sticks out %g mm "
                  "(--tool-stick-out): the holder would be lower than the tables know",
                  header.tool_flute_length_mm, job.tool_stick_out_mm);
    error = tables_name + text;
    return false;
  }
  return true;
}

}  // namespace stencil::board::sherline_suzuki
