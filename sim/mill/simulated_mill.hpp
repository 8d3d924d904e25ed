// The simulated Sherline 3-axis mill: motor steps to true axis positions with backlash, home switches,
// hard travel stops, stepper drivers enabled or not, spindle on or off. Simulated physics only, no I/O.
#pragma once

#include <array>
#include <cstdint>

namespace stencil::sim {

enum class Axis : std::uint8_t { x = 0, y = 1, z = 2 };
inline constexpr int kMillAxisCount = 3;

// The sign of one motor step. Positive moves the axis towards larger machine coordinates.
enum class StepDirection : std::int8_t { positive = 1, negative = -1 };

// One axis, every length in motor steps. A board gives them (the simulated Sherline mill's:
// board/sim/sim_facts.hpp, from the rig's facts).
struct MillAxisConfig {
  std::int64_t backlash_steps;       // play between screw and nut, taken up on every reversal
  std::int64_t travel_min_steps;     // low hard stop (the axis cannot go below it)
  std::int64_t travel_max_steps;     // high hard stop
  std::int64_t home_switch_edge_steps;  // the switch is closed while the axis is below this, open at/above it
  std::int64_t initial_position_steps;  // where the axis stands at power-up
  // 1: a positive motor step moves the axis to larger machine coordinates; -1: the motor is wired
  // backwards (a configuration's wrong axis sign), so every step goes the other way.
  int motor_direction = 1;
};

struct MillConfig {
  std::array<MillAxisConfig, kMillAxisCount> axes;
  double steps_per_mm;
};

// What one motor step did.
enum class StepOutcome : std::uint8_t {
  moved,               // the axis moved one step with the motor
  took_up_backlash,    // the motor turned inside the play; the axis stayed put
  stalled_at_limit,    // the axis is against a hard stop: the motor stalled, the step is lost
  drivers_disabled,    // the drivers are off: the motor did not turn
};

// Coordinates (the mill's own, machine coordinates): per axis, the axis position is the displacement
// of what that axis moves along the machine's + direction: the TABLE for X and Y, the HEAD (and tool)
// for Z. So a positive X or Y step moves the work +X/+Y under a fixed tool, i.e. the tool moves -X/-Y
// relative to the work; a positive Z step raises the tool. true_tool_position_in_table_mm() applies
// this: the tool tip relative to the table, with the origin where the tip is when every axis is at 0.
// Which way the planner maps world to machine is the planner's choice; this class states only physics.
//
// Backlash model: the motor (screw) position m and the axis (nut) position a, both in steps, satisfy
// m - backlash <= a <= m. A positive motor step pushes the axis only when a == m - backlash (so in
// steady positive motion a = m - backlash); a negative step pulls it only when a == m (steady negative
// motion: a = m). After a reversal the motor therefore turns exactly `backlash` steps before the axis
// moves. The motor position is the screw's angle expressed in axis steps, not a count from power-up.
//
// Told of every step that moved an axis (not take-ups, stalls or steps with the drivers off), with
// every axis's position after it: the ground truth of the path the tool followed.
class MillMotionObserver {
 public:
  virtual void axis_moved(Axis axis, const std::array<std::int64_t, kMillAxisCount>& axis_steps) = 0;

 protected:
  ~MillMotionObserver() = default;
};

// Not thread-safe; plain value state, no allocation.
class SimulatedMill {
 public:
  explicit SimulatedMill(const MillConfig& config);

  // One motor step on `axis` (the MMC-4S driver of that axis received a step pulse).
  StepOutcome step_motor(Axis axis, StepDirection direction);

  // Test set-up: stand the axis at `axis_steps` with its slack as after a move in `last_direction`.
  void place_axis(Axis axis, std::int64_t axis_steps, StepDirection last_direction);

  void set_drivers_enabled(bool enabled) { drivers_enabled_ = enabled; }
  [[nodiscard]] bool drivers_enabled() const { return drivers_enabled_; }
  void set_spindle_on(bool on) { spindle_on_ = on; }
  // Null for none. The observer must outlive its registration.
  void set_motion_observer(MillMotionObserver* observer) { observer_ = observer; }
  [[nodiscard]] bool spindle_on() const { return spindle_on_; }

  // True while the axis is below its home switch's edge.
  [[nodiscard]] bool home_switch_closed(Axis axis) const;
  // True when the axis is against its low or high hard stop.
  [[nodiscard]] bool at_travel_limit(Axis axis) const;

  // Ground truth.
  [[nodiscard]] std::int64_t axis_position_steps(Axis axis) const;
  [[nodiscard]] double axis_position_mm(Axis axis) const;
  [[nodiscard]] std::int64_t motor_position_steps(Axis axis) const;
  [[nodiscard]] std::array<double, kMillAxisCount> true_tool_position_in_table_mm() const;

  // Counters since construction.
  [[nodiscard]] std::int64_t steps_lost_at_limits(Axis axis) const;
  [[nodiscard]] std::int64_t steps_taking_up_backlash(Axis axis) const;
  [[nodiscard]] std::int64_t steps_ignored_while_disabled() const { return steps_ignored_while_disabled_; }

  [[nodiscard]] const MillConfig& config() const { return config_; }

 private:
  struct AxisState {
    std::int64_t motor_steps;
    std::int64_t axis_steps;
    std::int64_t lost_at_limits;
    std::int64_t backlash_steps_taken;
  };

  MillConfig config_;
  std::array<AxisState, kMillAxisCount> axes_{};
  bool drivers_enabled_ = false;
  bool spindle_on_ = false;
  std::int64_t steps_ignored_while_disabled_ = 0;
  MillMotionObserver* observer_ = nullptr;
};

}  // namespace stencil::sim
