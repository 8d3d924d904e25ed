#include "board/sherline_suzuki/commissioning.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace stencil::board::sherline_suzuki {
namespace {

constexpr const char* kAxisName = "XYZ";

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char text[320];
  std::snprintf(text, sizeof text, pattern, a, b, c, d);
  return text;
}

struct Commissioning {
  const RigFacts& facts;
  const CommissioningSettings& settings;
  hal::cy545::Cy545Link& link;
  hal::Clock& clock;
  CommissioningOperator& machinist;
  const std::atomic<bool>* interrupted;
  CommissioningResult result;

  [[nodiscard]] hal::MonotonicNs update() const { return update_ns(facts); }
  [[nodiscard]] bool asked_to_end() const { return interrupted != nullptr && interrupted->load(); }

  void keep_alive() { static_cast<void>(link.keep_alive(clock.now_ns() + update())); }

  // The axis to motor step `to` from home, in moves of at most one update's steps, as the machine side
  // moves it; nothing else moves, the spindle stays off.
  bool move_axis(int axis, std::int32_t to) {
    const auto a = static_cast<std::size_t>(axis);
    const auto chunk = static_cast<std::int32_t>(
        std::max(1.0, std::floor(0.9 * facts.step_rate_steps_per_s / facts.machine_update_hz)));
    hal::MachineTarget target{link.status().commanded_steps, {static_cast<std::uint8_t>(axis), 0, 0}, false};
    target.order = axis == 0 ? std::array<std::uint8_t, 3>{0, 1, 2}
                             : (axis == 1 ? std::array<std::uint8_t, 3>{1, 0, 2} : std::array<std::uint8_t, 3>{2, 0, 1});
    while (target.motor_steps[a] != to) {
      if (asked_to_end()) {
        result.findings.push_back("commissioning was stopped");
        return false;
      }
      target.motor_steps[a] += std::clamp(to - target.motor_steps[a], -chunk, chunk);
      if (!link.move(target, clock.now_ns() + 3 * update()).done) {
        result.findings.push_back(std::string("moving axis ") + kAxisName[a] + ": " + link.last_error());
        return false;
      }
      keep_alive();
    }
    if (!link.verify(clock.now_ns() + 3 * update()).done) {
      result.findings.push_back(std::string("axis ") + kAxisName[a] + ": " + link.last_error());
      return false;
    }
    return true;
  }

  bool read(int axis, const std::string& question, double& mm) {
    if (!machinist.reading(axis, question, [this] { keep_alive(); }, mm) || !std::isfinite(mm)) {
      result.findings.push_back(std::string("no reading for axis ") + kAxisName[axis] + ": commissioning ended");
      return false;
    }
    return true;
  }

  bool home() {
    machinist.say("commissioning: the spindle stays off. Homing, " + std::string(1, kAxisName[facts.homing_order[0]]) +
                  " first.");
    const hal::MonotonicNs deadline = clock.now_ns() + link.homing_bound_ns() + 10 * update();
    if (!link.start(deadline).done || !link.home(deadline).done) {
      result.findings.push_back(std::string("homing: ") + link.last_error());
      return false;
    }
    result.homed = true;
    machinist.say("commissioning: homed. Each axis now moves " + format("%g", settings.jog_mm) +
                  " mm into its travel and back half of that; read a dial indicator set along it.");
    return true;
  }

  // Which way and how far the axis went for `jog_mm` into its travel, then what the reversal lost.
  bool axis(int axis) {
    const auto a = static_cast<std::size_t>(axis);
    const double expected = facts.machine_sign[a] * settings.jog_mm;  // world mm for machine +jog
    const auto jog = static_cast<std::int32_t>(std::lround(settings.jog_mm * facts.steps_per_mm));
    double at_home = 0.0, out = 0.0, back = 0.0;
    const std::string name(1, kAxisName[a]);
    if (!read(axis, "axis " + name + " at home: the indicator's reading (mm, + along the part's +" + name + ")", at_home) ||
        !move_axis(axis, jog) ||
        !read(axis, "axis " + name + format(" moved (it should have gone %+g mm along the part's axis): the reading", expected),
              out) ||
        !move_axis(axis, jog / 2) || !read(axis, "axis " + name + " came back half of it: the reading", back) ||
        !move_axis(axis, 0)) {
      return false;
    }
    const double moved = out - at_home;
    result.moved_mm[a] = moved;
    if (moved * expected <= 0.0 || std::fabs(moved) < 0.25 * settings.jog_mm) {
      result.findings.push_back("axis " + name + format(": moved %+.3f mm along the part's axis for %+.3f commanded: it runs "
                                                        "the other way (or not at all); check machine.axis_sign",
                                                        moved, expected));
      return true;
    }
    if (std::fabs(std::fabs(moved) - settings.jog_mm) > settings.tolerance_mm) {
      const double percent = 100.0 * (std::fabs(moved) - settings.jog_mm) / settings.jog_mm;
      char text[240];
      std::snprintf(text, sizeof text,
                    ": moved %.3f mm for %.3f mm commanded (%+.2f %%): machine.steps_per_mm would be %.2f; the file says %g",
                    std::fabs(moved), settings.jog_mm, percent, facts.steps_per_mm * settings.jog_mm / std::fabs(moved),
                    facts.steps_per_mm);
      result.findings.push_back("axis " + name + text);
    }
    // The way back turns the play out before the axis moves: what is missing of the half is the backlash.
    const double scale = std::fabs(moved) / settings.jog_mm;
    const double lost = std::max(0.0, scale * (jog - jog / 2) / facts.steps_per_mm - std::fabs(back - out));
    result.backlash_mm[a] = std::round(lost * facts.steps_per_mm) / facts.steps_per_mm;
    return true;
  }
};

}  // namespace

CommissioningResult commission(const RigFacts& facts, const CommissioningSettings& settings, hal::cy545::Cy545Link& link,
                               hal::Clock& clock, CommissioningOperator& machinist, const std::atomic<bool>* interrupted) {
  Commissioning run{facts, settings, link, clock, machinist, interrupted, {}};
  link.abort_on(interrupted);
  bool whole = run.home();
  for (int axis = 0; whole && axis < kAxisCount; ++axis) {
    whole = run.axis(axis);
  }
  static_cast<void>(link.stop(clock.now_ns() + 3 * run.update()));
  CommissioningResult& result = run.result;
  if (whole) {
    result.backlash_line = format("backlash_mm = [%.10g, %.10g, %.10g]", result.backlash_mm[0], result.backlash_mm[1],
                                  result.backlash_mm[2]);
    // A difference the indicator can tell: one step (1.6 um here) is finer than a dial reads.
    bool differs = false;
    for (std::size_t axis = 0; axis < 3; ++axis) {
      differs = differs || std::fabs(result.backlash_mm[axis] - facts.backlash_mm[axis]) > settings.tolerance_mm;
    }
    if (differs) {
      result.findings.push_back("measured backlash: put `" + result.backlash_line + "` in [machine] (the file says " +
                                format("[%g, %g, %g])", facts.backlash_mm[0], facts.backlash_mm[1], facts.backlash_mm[2]));
    }
  }
  result.passed = whole && result.findings.empty();
  return result;
}

std::string describe(const CommissioningResult& result) {
  std::string text;
  for (const std::string& finding : result.findings) {
    text += "commissioning: " + finding + "\n";
  }
  if (!result.backlash_line.empty()) {
    text += "commissioning: measured " + result.backlash_line + "\n";
  }
  text += result.passed ? "commissioning: passed: the configuration agrees with the mill\n"
                        : "commissioning: FAILED: correct the configuration before any cut\n";
  return text;
}

}  // namespace stencil::board::sherline_suzuki
