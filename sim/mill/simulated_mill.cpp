// The simulated Sherline mill: backlash, hard stops and home switches per axis.
#include "sim/mill/simulated_mill.hpp"

#include <cstddef>

namespace stencil::sim {

namespace {

std::size_t index_of(Axis axis) { return static_cast<std::size_t>(axis); }

}  // namespace

SimulatedMill::SimulatedMill(const MillConfig& config) : config_(config) {
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    place_axis(static_cast<Axis>(i), config_.axes[i].initial_position_steps, StepDirection::positive);
  }
}

void SimulatedMill::place_axis(Axis axis, std::int64_t axis_steps, StepDirection last_direction) {
  AxisState& state = axes_[index_of(axis)];
  state.axis_steps = axis_steps;
  state.motor_steps =
      last_direction == StepDirection::positive ? axis_steps + config_.axes[index_of(axis)].backlash_steps : axis_steps;
}

StepOutcome SimulatedMill::step_motor(Axis axis, StepDirection direction) {
  if (!drivers_enabled_) {
    ++steps_ignored_while_disabled_;
    return StepOutcome::drivers_disabled;
  }
  const MillAxisConfig& limits = config_.axes[index_of(axis)];
  AxisState& state = axes_[index_of(axis)];
  const std::int64_t motor = state.motor_steps + static_cast<std::int64_t>(direction) * limits.motor_direction;
  // The nut sits in [motor - backlash, motor]; it moves only when the screw pushes it.
  std::int64_t nut = state.axis_steps;
  if (nut < motor - limits.backlash_steps) nut = motor - limits.backlash_steps;
  if (nut > motor) nut = motor;
  if (nut < limits.travel_min_steps || nut > limits.travel_max_steps) {
    ++state.lost_at_limits;
    return StepOutcome::stalled_at_limit;
  }
  state.motor_steps = motor;
  if (nut == state.axis_steps) {
    ++state.backlash_steps_taken;
    return StepOutcome::took_up_backlash;
  }
  state.axis_steps = nut;
  if (observer_ != nullptr) {
    observer_->axis_moved(axis, {axes_[0].axis_steps, axes_[1].axis_steps, axes_[2].axis_steps});
  }
  return StepOutcome::moved;
}

bool SimulatedMill::home_switch_closed(Axis axis) const {
  return axes_[index_of(axis)].axis_steps < config_.axes[index_of(axis)].home_switch_edge_steps;
}

bool SimulatedMill::at_travel_limit(Axis axis) const {
  const std::int64_t position = axes_[index_of(axis)].axis_steps;
  const MillAxisConfig& limits = config_.axes[index_of(axis)];
  return position <= limits.travel_min_steps || position >= limits.travel_max_steps;
}

std::int64_t SimulatedMill::axis_position_steps(Axis axis) const { return axes_[index_of(axis)].axis_steps; }

double SimulatedMill::axis_position_mm(Axis axis) const {
  return static_cast<double>(axes_[index_of(axis)].axis_steps) / config_.steps_per_mm;
}

std::int64_t SimulatedMill::motor_position_steps(Axis axis) const { return axes_[index_of(axis)].motor_steps; }

std::array<double, kMillAxisCount> SimulatedMill::true_tool_position_in_table_mm() const {
  // X and Y move the table under the tool, Z moves the tool itself.
  return {-axis_position_mm(Axis::x), -axis_position_mm(Axis::y), axis_position_mm(Axis::z)};
}

std::int64_t SimulatedMill::steps_lost_at_limits(Axis axis) const { return axes_[index_of(axis)].lost_at_limits; }

std::int64_t SimulatedMill::steps_taking_up_backlash(Axis axis) const {
  return axes_[index_of(axis)].backlash_steps_taken;
}

}  // namespace stencil::sim
