// Commissioning a new or changed configuration, with the spindle off: the mill homes (Z first; an
// axis whose motor runs the other way never reaches its switch, and homing says to check its sign),
// then each axis moves a configured distance into its travel and back half of it while the operator
// reads a dial indicator: the readings say which way the axis really went (its sign), how far (its
// steps per mm) and how much the reversal lost (its backlash, proposed as the file's line).
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "board/sherline_suzuki/rig_facts.hpp"
#include "hal/clock.hpp"
#include "hal/cy545/cy545_link.hpp"

namespace stencil::board::sherline_suzuki {

struct CommissioningSettings {
  double jog_mm = 5.0;         // how far each axis moves into its travel (then back half of it)
  double tolerance_mm = 0.02;  // a reading this far from the commanded move is a finding
};

// Whoever reads the dial indicator: the machinist at the terminal, or in the simulation a simulated
// one reading the simulated mill's truth.
class CommissioningOperator {
 public:
  virtual void say(const std::string& line) = 0;
  // The indicator's reading on `axis` (mm, + along the part's + axis), asked with `question`; `idle`
  // is to be called at least every 100 ms while waiting (it keeps the watchdog relay's heartbeat).
  // False: no reading (input closed, or the job is to end).
  virtual bool reading(int axis, const std::string& question, const std::function<void()>& idle, double& mm) = 0;

 protected:
  ~CommissioningOperator() = default;
};

struct CommissioningResult {
  bool homed = false;
  bool passed = false;                      // homed, and every axis went the way and the distance configured
  std::vector<std::string> findings;        // what disagrees, one line each, with what to check
  std::array<double, 3> moved_mm{};         // each axis's reading for the commanded jog (world mm)
  std::array<double, 3> backlash_mm{};      // measured, rounded to whole steps
  std::string backlash_line;                // the file's line with the measured backlash
};

// Runs it on an opened link (`clock` its time); `interrupted` ends it between moves. The link is
// stopped (drivers and spindle off) at the end, whatever happened.
[[nodiscard]] CommissioningResult commission(const RigFacts& facts, const CommissioningSettings& settings,
                                             hal::cy545::Cy545Link& link, hal::Clock& clock,
                                             CommissioningOperator& machinist, const std::atomic<bool>* interrupted);

// What it found, for the machinist: a line per finding, the measured backlash line, and the verdict,
// each line starting "commissioning: ".
[[nodiscard]] std::string describe(const CommissioningResult& result);

}  // namespace stencil::board::sherline_suzuki
