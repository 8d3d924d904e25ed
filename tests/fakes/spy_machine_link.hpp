// SpyMachineLink: a mill that does at once whatever it is told and remembers every target it was
// sent (each move completes before the next update). For the machine side's tests: what reached
// the mill, in which order, and what the record held at that moment (through a callback).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "hal/machine_link.hpp"

namespace stencil::test {

class SpyMachineLink final : public hal::MachineLink {
 public:
  // Called with each target as it is sent, before it is stored.
  std::function<void(const hal::MachineTarget&)> on_move;

  [[nodiscard]] const std::vector<hal::MachineTarget>& moves() const { return moves_; }
  [[nodiscard]] int stops() const { return stops_; }

  hal::MachineResult start(hal::MonotonicNs) override { return done(); }
  void abort_on(const std::atomic<bool>*) override {}
  [[nodiscard]] hal::MonotonicNs homing_bound_ns() const override { return 1'000'000'000; }
  hal::MachineResult home(hal::MonotonicNs) override {
    status_.state = hal::MachineState::Homed;
    status_.homed = true;
    return done();
  }
  hal::MachineResult declare_home(hal::MonotonicNs deadline_ns) override { return home(deadline_ns); }
  hal::MachineResult move(const hal::MachineTarget& target, hal::MonotonicNs) override {
    if (status_.state == hal::MachineState::Held) {
      ++refused_while_held_;  // as the CY545 link: a held feed refuses moves (a MachineSide that sent one is wrong)
      return {false, hal::MachineRefusal::Held, hal::MachineFault::None};
    }
    if (on_move) {
      on_move(target);
    }
    moves_.push_back(target);
    status_.commanded_steps = target.motor_steps;
    ++status_.moves_done;  // done by the next update
    return done();
  }
  hal::MachineResult verify(hal::MonotonicNs) override { return done(); }
  hal::MachineResult set_spindle(bool on, hal::MonotonicNs) override {
    status_.spindle_on = on;
    return done();
  }
  hal::MachineResult keep_alive(hal::MonotonicNs) override {
    ++keep_alives_;
    return done();
  }
  [[nodiscard]] int keep_alives() const { return keep_alives_; }
  void hold() override { status_.state = hal::MachineState::Held; }
  void resume() override { status_.state = hal::MachineState::Homed; }
  hal::MachineResult stop(hal::MonotonicNs) override {
    ++stops_;
    status_.state = hal::MachineState::Stopped;
    status_.spindle_on = false;
    return done();
  }
  [[nodiscard]] hal::MachineStatus status() const override { return status_; }
  [[nodiscard]] int refused_while_held() const { return refused_while_held_; }
  [[nodiscard]] std::array<int, 3> home_approach() const override { return {-1, -1, -1}; }

 private:
  int refused_while_held_ = 0;
  int keep_alives_ = 0;
  static hal::MachineResult done() { return {true, hal::MachineRefusal::None, hal::MachineFault::None}; }
  hal::MachineStatus status_{hal::MachineState::Ready, hal::MachineFault::None, {0, 0, 0}, false, false, true, 0, 0, 0};
  std::vector<hal::MachineTarget> moves_;
  int stops_ = 0;
};

}  // namespace stencil::test
