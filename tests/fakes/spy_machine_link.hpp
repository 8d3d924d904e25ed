// SpyMachineLink: a MachineLink that writes down every call made to it, in order and with its
// arguments, answers as a test scripts it, and otherwise keeps the contract hal/machine_link.hpp
// documents, as the CY545 link (hal/cy545/cy545_link.cpp) keeps it:
//   - start() from Open (or any later state) gives Ready: outputs off, not homed;
//   - home() and declare_home() need start() first (NotHomed from Open), then give Homed at step 0;
//   - move() is refused (nothing recorded as sent) when faulted (Faulted), held (Held), not homed or
//     stopped (NotHomed), cutting with the spindle off (SpindleOff), or with an order that is not a
//     permutation or steps beyond the CY545's count (BadTarget); in that order, as the CY545 checks;
//   - hold() only holds a homed link, resume() only lifts a hold;
//   - stop() is hold + spindle off + drivers off + not homed (home again before moving), and does so
//     whatever fault is latched (the fault stays latched and the state Fault);
//   - a latched fault (a scripted answer carrying one, or latch_fault()) sets status() to Fault, unhomes
//     the link and has every later call but stop() refused Faulted, for good.
// Where it differs from the real link: it has no port, no clock and no speed: every move completes
// at once (status().moves_done counts it before move() returns, unless complete_moves_at_once is
// cleared), no call is refused DeadlineTooShort or TooLong (unless max_move_steps is set), homing
// takes no time (so homing_bound_ns() is a token 1 s), keep_alive() is counted but toggles nothing,
// start() never blocks, and abort_on()'s flag is looked at once per start() or homing call (given up
// there: outputs off, Stopped, refusal Aborted). bytes_sent and bytes_received stay 0.
// A scripted answer replaces the contract's for one call of its kind (see answer_next()).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <functional>
#include <vector>

#include "hal/machine_link.hpp"

namespace stencil::test {

// The MachineLink calls, one per method that acts (status(), home_approach() and homing_bound_ns()
// only look, and are not written down).
enum class MachineCall : std::uint8_t { Start, AbortOn, Home, DeclareHome, Move, Verify, SetSpindle, KeepAlive, Hold, Resume, Stop };
inline constexpr std::size_t kMachineCallKinds = 11;

[[nodiscard]] constexpr const char* machine_call_name(MachineCall call) {
  switch (call) {
    case MachineCall::Start:
      return "start";
    case MachineCall::AbortOn:
      return "abort_on";
    case MachineCall::Home:
      return "home";
    case MachineCall::DeclareHome:
      return "declare_home";
    case MachineCall::Move:
      return "move";
    case MachineCall::Verify:
      return "verify";
    case MachineCall::SetSpindle:
      return "set_spindle";
    case MachineCall::KeepAlive:
      return "keep_alive";
    case MachineCall::Hold:
      return "hold";
    case MachineCall::Resume:
      return "resume";
    case MachineCall::Stop:
      return "stop";
  }
  return "unknown";
}

// One call as it came, and what it was answered (hold, resume and abort_on answer nothing: done).
struct SpyCall {
  MachineCall kind;
  hal::MonotonicNs deadline_ns;  // 0 for the calls without one
  hal::MachineTarget target;     // Move: the target asked (sent or not); else zeros
  bool spindle_on;               // SetSpindle: on or off asked
  hal::MachineResult result;
};

class SpyMachineLink final : public hal::MachineLink {
 public:
  // Called with each target the link accepts, before it is stored in moves().
  std::function<void(const hal::MachineTarget&)> on_move;
  // Cleared: moves are accepted but not completed (status().moves_done stays) until complete_moves().
  bool complete_moves_at_once = true;
  // A move of more motor steps than this (all axes together) is refused TooLong: the real link's
  // one-update bound, which the spy does not know by itself.
  std::int64_t max_move_steps = INT64_MAX;
  // Steps the CY545 can count either way (its 24-bit register, half of it): beyond is BadTarget.
  std::int32_t max_abs_steps = (1 << 23) - 1;
  // What home_approach() reports (the planner puts the backlash slack on this side).
  std::array<int, 3> approach{-1, -1, -1};

  // The next call of `kind` answers `result` instead of what the contract would. A result with a
  // fault latches it (as a real link latches what went wrong on the port) and does nothing else; a
  // refusal does nothing; done does what the call does, without the contract's checks (for a test
  // that needs the link to accept what it would refuse). Queued: one per call, in order.
  void answer_next(MachineCall kind, hal::MachineResult result) { scripted_[index(kind)].push_back(result); }
  // The next call of `kind` finds `fault` and latches it.
  void fail_next(MachineCall kind, hal::MachineFault fault) { answer_next(kind, {false, hal::MachineRefusal::None, fault}); }
  // A fault found between calls (the port hung up): latched now, as if by the link's last call.
  void latch_fault(hal::MachineFault fault) {
    if (status_.fault == hal::MachineFault::None) {
      status_.fault = fault;
    }
    status_.state = hal::MachineState::Fault;
    status_.homed = false;
  }
  // Completes `count` accepted moves (with complete_moves_at_once cleared), no more than were sent.
  void complete_moves(std::uint64_t count) {
    const std::uint64_t pending = moves_.size() - status_.moves_done;
    status_.moves_done += count < pending ? count : pending;
  }

  // What was asked, in order.
  [[nodiscard]] const std::vector<SpyCall>& calls() const { return calls_; }
  [[nodiscard]] std::vector<MachineCall> call_kinds() const {
    std::vector<MachineCall> kinds;
    for (const SpyCall& call : calls_) {
      kinds.push_back(call.kind);
    }
    return kinds;
  }
  [[nodiscard]] int count(MachineCall kind) const {
    int n = 0;
    for (const SpyCall& call : calls_) {
      n += call.kind == kind ? 1 : 0;
    }
    return n;
  }
  // The targets the link accepted (what reached the mill), in order.
  [[nodiscard]] const std::vector<hal::MachineTarget>& moves() const { return moves_; }
  [[nodiscard]] int stops() const { return count(MachineCall::Stop); }
  [[nodiscard]] int keep_alives() const { return count(MachineCall::KeepAlive); }
  // Moves refused because the feed was held (a MachineSide that sends one while holding is wrong).
  [[nodiscard]] int refused_while_held() const { return refused_while_held_; }
  [[nodiscard]] const std::atomic<bool>* abort_flag() const { return abort_; }

  hal::MachineResult start(hal::MonotonicNs deadline_ns) override {
    hal::MachineResult result = done();
    if (!scripted(MachineCall::Start, result)) {
      if (faulted()) {
        result = refuse(hal::MachineRefusal::Faulted);
      } else if (abort_asked()) {
        result = aborted();  // as the CY545 link: what an earlier run left on is turned off first
      } else {
        accept_start();
      }
    } else if (result.done) {
      accept_start();
    }
    return note({MachineCall::Start, deadline_ns, {}, false, result});
  }
  void abort_on(const std::atomic<bool>* flag) override {
    abort_ = flag;
    static_cast<void>(note({MachineCall::AbortOn, 0, {}, false, done()}));
  }
  [[nodiscard]] hal::MonotonicNs homing_bound_ns() const override { return 1'000'000'000; }
  hal::MachineResult home(hal::MonotonicNs deadline_ns) override { return homing(MachineCall::Home, deadline_ns); }
  hal::MachineResult declare_home(hal::MonotonicNs deadline_ns) override { return homing(MachineCall::DeclareHome, deadline_ns); }
  hal::MachineResult move(const hal::MachineTarget& target, hal::MonotonicNs deadline_ns) override {
    hal::MachineResult result = done();
    if (!scripted(MachineCall::Move, result)) {
      result = move_refusal(target);
      refused_while_held_ += result.refusal == hal::MachineRefusal::Held ? 1 : 0;
    }
    if (result.done) {
      accept_move(target);
    }
    return note({MachineCall::Move, deadline_ns, target, false, result});
  }
  hal::MachineResult verify(hal::MonotonicNs deadline_ns) override {
    hal::MachineResult result = done();
    if (!scripted(MachineCall::Verify, result) && faulted()) {
      result = refuse(hal::MachineRefusal::Faulted);
    }
    return note({MachineCall::Verify, deadline_ns, {}, false, result});
  }
  hal::MachineResult set_spindle(bool on, hal::MonotonicNs deadline_ns) override {
    hal::MachineResult result = done();
    if (!scripted(MachineCall::SetSpindle, result)) {
      result = faulted()    ? refuse(hal::MachineRefusal::Faulted)
               : started() ? done()
                           : refuse(hal::MachineRefusal::NotHomed);
    }
    if (result.done) {
      status_.spindle_on = on;
    }
    return note({MachineCall::SetSpindle, deadline_ns, {}, on, result});
  }
  hal::MachineResult keep_alive(hal::MonotonicNs deadline_ns) override {
    hal::MachineResult result = done();
    if (!scripted(MachineCall::KeepAlive, result)) {
      result = faulted()    ? refuse(hal::MachineRefusal::Faulted)
               : started() ? done()
                           : refuse(hal::MachineRefusal::NotHomed);
    }
    return note({MachineCall::KeepAlive, deadline_ns, {}, false, result});
  }
  void hold() override {
    hold_if_homed();
    static_cast<void>(note({MachineCall::Hold, 0, {}, false, done()}));
  }
  void resume() override {
    if (status_.state == hal::MachineState::Held) {
      status_.state = hal::MachineState::Homed;
    }
    static_cast<void>(note({MachineCall::Resume, 0, {}, false, done()}));
  }
  // Whatever fault is latched, as the CY545's: the outputs go off and it says so (done). A scripted
  // failure is a stop that could not confirm them off: spindle and drivers stay as they were.
  hal::MachineResult stop(hal::MonotonicNs deadline_ns) override {
    hold_if_homed();
    status_.homed = false;  // limp axes may have moved: home again
    hal::MachineResult result{true, hal::MachineRefusal::None, status_.fault};
    const bool answered = scripted(MachineCall::Stop, result);
    if (!answered || result.done) {
      status_.spindle_on = false;
      status_.drivers_on = false;
      if (!faulted()) {
        status_.state = hal::MachineState::Stopped;
      }
    }
    return note({MachineCall::Stop, deadline_ns, {}, false, result});
  }
  [[nodiscard]] hal::MachineStatus status() const override { return status_; }
  [[nodiscard]] std::array<int, 3> home_approach() const override { return approach; }

 private:
  static hal::MachineResult done() { return {true, hal::MachineRefusal::None, hal::MachineFault::None}; }
  static hal::MachineResult refuse(hal::MachineRefusal refusal) { return {false, refusal, hal::MachineFault::None}; }
  static std::size_t index(MachineCall kind) { return static_cast<std::size_t>(kind); }
  [[nodiscard]] bool faulted() const { return status_.fault != hal::MachineFault::None; }
  [[nodiscard]] bool started() const { return status_.state != hal::MachineState::Closed && status_.state != hal::MachineState::Open; }

  // Takes the next scripted answer of `kind` into `result`, latching its fault; false when none.
  bool scripted(MachineCall kind, hal::MachineResult& result) {
    std::deque<hal::MachineResult>& queue = scripted_[index(kind)];
    if (queue.empty()) {
      return false;
    }
    result = queue.front();
    queue.pop_front();
    if (result.fault != hal::MachineFault::None) {
      latch_fault(result.fault);
    }
    return true;
  }
  hal::MachineResult note(const SpyCall& call) {
    calls_.push_back(call);
    return call.result;
  }
  [[nodiscard]] bool abort_asked() const { return abort_ != nullptr && abort_->load(); }
  // A stop asked while starting or homing: outputs off, stopped, home again (refusal Aborted).
  hal::MachineResult aborted() {
    status_.state = hal::MachineState::Stopped;
    status_.homed = false;
    status_.spindle_on = false;
    status_.drivers_on = false;
    return refuse(hal::MachineRefusal::Aborted);
  }
  void accept_start() {
    status_.state = hal::MachineState::Ready;
    status_.homed = false;
    status_.spindle_on = false;
    status_.drivers_on = false;
  }
  hal::MachineResult homing(MachineCall kind, hal::MonotonicNs deadline_ns) {
    hal::MachineResult result = done();
    if (!scripted(kind, result)) {
      result = faulted()       ? refuse(hal::MachineRefusal::Faulted)
               : !started()    ? refuse(hal::MachineRefusal::NotHomed)
               : abort_asked() ? aborted()
                               : done();
    }
    if (result.done) {
      status_.state = hal::MachineState::Homed;
      status_.homed = true;
      status_.drivers_on = true;
      status_.commanded_steps = {0, 0, 0};
    }
    return note({kind, deadline_ns, {}, false, result});
  }
  [[nodiscard]] hal::MachineResult move_refusal(const hal::MachineTarget& target) const {
    if (faulted()) {
      return refuse(hal::MachineRefusal::Faulted);
    }
    if (status_.state == hal::MachineState::Held) {
      return refuse(hal::MachineRefusal::Held);
    }
    if (!status_.homed || status_.state != hal::MachineState::Homed) {
      return refuse(hal::MachineRefusal::NotHomed);
    }
    if (target.cutting && !status_.spindle_on) {
      return refuse(hal::MachineRefusal::SpindleOff);
    }
    const auto& order = target.order;
    if (order[0] > 2 || order[1] > 2 || order[2] > 2 || order[0] == order[1] || order[1] == order[2] || order[0] == order[2]) {
      return refuse(hal::MachineRefusal::BadTarget);
    }
    std::int64_t total = 0;
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (std::abs(static_cast<std::int64_t>(target.motor_steps[axis])) > max_abs_steps) {
        return refuse(hal::MachineRefusal::BadTarget);
      }
      total += std::abs(static_cast<std::int64_t>(target.motor_steps[axis]) - status_.commanded_steps[axis]);
    }
    return total > max_move_steps ? refuse(hal::MachineRefusal::TooLong) : done();
  }
  void accept_move(const hal::MachineTarget& target) {
    if (on_move) {
      on_move(target);
    }
    moves_.push_back(target);
    status_.commanded_steps = target.motor_steps;
    if (complete_moves_at_once) {
      ++status_.moves_done;  // done before the next update
    }
  }
  void hold_if_homed() {
    if (status_.state == hal::MachineState::Homed) {
      status_.state = hal::MachineState::Held;
    }
  }

  hal::MachineStatus status_{hal::MachineState::Open, hal::MachineFault::None, {0, 0, 0}, false, false, false, 0, 0, 0};
  std::vector<SpyCall> calls_;
  std::vector<hal::MachineTarget> moves_;
  std::array<std::deque<hal::MachineResult>, kMachineCallKinds> scripted_{};
  const std::atomic<bool>* abort_ = nullptr;
  int refused_while_held_ = 0;
};

}  // namespace stencil::test
